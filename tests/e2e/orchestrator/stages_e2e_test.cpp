// A staged case (case.yaml `stages`, issue 41 item 2): settle with the gas at rest, then blow, as
// one command. The run stopped inside the first stage (--stop-after) resumes it from its
// checkpoint and then runs the second stage from the first one's end: the second stage's first
// snapshot is the first stage's last, bit for bit. A finished staged run resumes to nothing;
// `check` checks every stage; a later stage that sets particles is refused naming the line.
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "coredem_e2e.h"
#include "coredem_e2e_hdf5.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

const fs::path kBin = COREDEM_BIN_DIR;
const fs::path kCases = COREDEM_E2E_CASES;

using coredem::e2e::datasetsOf;
using coredem::e2e::lastSnapshot;
using coredem::e2e::readAll;
using coredem::e2e::replaceAll;
using coredem::e2e::writeAll;

int runCoredem(const std::vector<std::string>& args, const fs::path& log) {
  return coredem::e2e::waitExit(coredem::e2e::startProgram(kBin / "coredem", args, log), 120s);
}

/// The restart case (64 beads in a box, prescribed gas) with two stages.
fs::path stagedCase(const fs::path& dir, const std::string& stages) {
  fs::create_directories(dir);
  writeAll(dir / "case.yaml", readAll(kCases / "restart" / "case.yaml") + stages);
  return dir;
}

const char* kTwoStages = R"(stages:
  - {name: settle, time.end: 0.02, gas.u_g: [0.0, 0.0, 0.0]}
  - {name: blow, time.end: 0.01, gas.u_g: [0.0, 0.0, 0.5]}
)";

} // namespace

TEST(StagesE2E, SettleThenBlowRunsAsOneCommandAndResumesAcrossStages) {
  const fs::path d = coredem::e2e::tempDir("coredem-e2e", "stages");
  const fs::path c = stagedCase(d / "case", kTwoStages);
  EXPECT_EQ(runCoredem({"check", c.string()}, d / "check.log"), 0) << readAll(d / "check.log");
  EXPECT_NE(readAll(d / "check.log").find("valid (2 stages)"), std::string::npos)
      << readAll(d / "check.log");

  const fs::path run = d / "run";
  ASSERT_EQ(
      runCoredem({"run", c.string(), "--out", run.string(), "--no-plots", "--stop-after", "20"},
                 d / "run.log"),
      0)
      << readAll(d / "run.log");
  const fs::path settle = run / "stages" / "01-settle";
  const fs::path blow = run / "stages" / "02-blow";
  EXPECT_FALSE(fs::exists(settle / "done")) << "the first stage was stopped at step 20";
  EXPECT_FALSE(fs::exists(blow)) << "the second stage started before the first ended";

  ASSERT_EQ(runCoredem({"resume", run.string(), "--no-plots"}, d / "resume.log"), 0)
      << readAll(d / "resume.log");
  ASSERT_TRUE(fs::exists(settle / "done")) << readAll(d / "resume.log");
  ASSERT_TRUE(fs::exists(blow / "done")) << readAll(d / "resume.log");
  const std::string second = readAll(blow / "case" / "case.yaml");
  EXPECT_NE(second.find("initial_state: ../../01-settle/run"), std::string::npos) << second;
  EXPECT_EQ(second.find("particles:"), std::string::npos) << second;
  EXPECT_NE(second.find("u_g: [0.0, 0.0, 0.5]"), std::string::npos) << second;
  const auto ts = coredem::e2e::readTimeseries(settle / "run");
  EXPECT_NEAR(ts.at("t").back(), 0.02, 1e-12);
  EXPECT_NEAR(coredem::e2e::readTimeseries(blow / "run").at("t").back(), 0.01, 1e-12);

  // The second stage starts from the first stage's end, bit for bit.
  const auto a = datasetsOf(lastSnapshot(settle / "run"));
  const auto b = datasetsOf(blow / "run" / "snapshots" / "particles_00000000.h5");
  for (const char* field : {"particles/position", "particles/velocity", "particles/temperature"}) {
    ASSERT_TRUE(a.count(field) && b.count(field)) << field;
    EXPECT_EQ(a.at(field), b.at(field)) << field;
  }
  // A finished staged run resumes to nothing.
  EXPECT_EQ(runCoredem({"resume", run.string(), "--no-plots"}, d / "again.log"), 0)
      << readAll(d / "again.log");
  EXPECT_NE(readAll(d / "again.log").find("stage 2/2 'blow' is done"), std::string::npos)
      << readAll(d / "again.log");
  if (!HasFailure()) {
    fs::remove_all(d);
  }
}

TEST(StagesE2E, ALaterStageThatSetsParticlesIsRefusedNamingTheLine) {
  const fs::path d = coredem::e2e::tempDir("coredem-e2e", "stages-bad");
  const fs::path c = stagedCase(d / "case", R"(stages:
  - {name: settle}
  - name: blow
    particles[0].count: 5
)");
  EXPECT_EQ(runCoredem({"check", c.string()}, d / "check.log"), 2) << readAll(d / "check.log");
  EXPECT_NE(readAll(d / "check.log")
                .find("stages[1].particles[0].count: a later stage starts "
                      "from the previous stage's particles"),
            std::string::npos)
      << readAll(d / "check.log");
  const fs::path c2 = stagedCase(d / "case2", R"(stages:
  - {name: settle, time.end: -1.0}
)");
  EXPECT_EQ(runCoredem({"run", c2.string(), "--out", (d / "run").string()}, d / "run.log"), 2)
      << readAll(d / "run.log");
  EXPECT_NE(readAll(d / "run.log").find("stage 1 'settle'"), std::string::npos)
      << readAll(d / "run.log");
  EXPECT_FALSE(fs::exists(d / "run" / "staged.yaml")) << "a refused stage left a run folder";
  if (!HasFailure()) {
    fs::remove_all(d);
  }
}
