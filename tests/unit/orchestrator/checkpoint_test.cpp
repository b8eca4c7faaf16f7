// Checkpoint manifests: atomic write, verification, resume selection, pruning.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <unistd.h>

#include <coredem/orchestrator/checkpoint.h>
#include <coredem/orchestrator/sha256.h>

using namespace coredem::orchestrator;
namespace fs = std::filesystem;

namespace {

struct TempRun {
  fs::path dir;
  TempRun() {
    dir = fs::temp_directory_path() /
          ("coredem-ckpt-test-" + std::to_string(::getpid()) + "-" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~TempRun() { fs::remove_all(dir); }
};

void writeText(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

fs::path makeCheckpoint(const fs::path& run, std::int64_t step, bool withManifest = true) {
  const fs::path dir = checkpointDir(run, step);
  writeText(dir / "dem.h5", "dem state " + std::to_string(step));
  writeText(dir / "gas.h5", "gas state " + std::to_string(step));
  if (withManifest) {
    Manifest m;
    m.step = step;
    m.time = 1e-4 * double(step);
    m.timeCompensation = -1.25e-20;
    m.lastDt = 1e-4;
    m.softwareVersion = "0.1.0";
    m.protocolVersion = "1.0";
    m.configHash = sha256Hex("case");
    writeManifest(dir, m, {{"dem.h5", "dem"}, {"gas.h5", "cfd"}});
  }
  return dir;
}

} // namespace

TEST(Checkpoint, ManifestRoundTripIsExact) {
  TempRun run;
  const fs::path dir = makeCheckpoint(run.dir, 100);
  const Manifest m = readManifest(dir);
  EXPECT_EQ(m.step, 100);
  EXPECT_EQ(m.time, 1e-4 * 100.0); // bitwise, through the hex-float text
  EXPECT_EQ(m.timeCompensation, -1.25e-20);
  ASSERT_EQ(m.files.size(), 2u);
  EXPECT_EQ(m.files[0].path, "dem.h5");
  EXPECT_EQ(m.files[0].sha256, sha256Hex("dem state 100"));
  EXPECT_EQ(m.files[1].participant, "cfd");
  EXPECT_EQ(verifyCheckpoint(dir), "");
  // No temp files left behind.
  for (const auto& e : fs::directory_iterator(dir)) {
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos);
  }
}

TEST(Checkpoint, ResumeSkipsIncompleteAndCorrupted) {
  TempRun run;
  makeCheckpoint(run.dir, 100);
  makeCheckpoint(run.dir, 200);
  const fs::path corrupted = makeCheckpoint(run.dir, 300);
  makeCheckpoint(run.dir, 400, /*withManifest=*/false);
  // Flip content of one file of 300 with the same size.
  writeText(corrupted / "gas.h5", "gas state 999");
  const ResumeChoice c = selectResumeCheckpoint(run.dir);
  ASSERT_TRUE(c.dir.has_value());
  EXPECT_EQ(*c.dir, checkpointDir(run.dir, 200));
  EXPECT_EQ(c.manifest->step, 200);
  ASSERT_EQ(c.skipped.size(), 2u);
  EXPECT_EQ(c.skipped[0].dir, checkpointDir(run.dir, 400));
  EXPECT_NE(c.skipped[0].reason.find("no manifest"), std::string::npos) << c.skipped[0].reason;
  EXPECT_EQ(c.skipped[1].dir, checkpointDir(run.dir, 300));
  EXPECT_NE(c.skipped[1].reason.find("gas.h5: SHA-256 does not match"), std::string::npos)
      << c.skipped[1].reason;
}

TEST(Checkpoint, TruncatedFileIsReportedBySize) {
  TempRun run;
  const fs::path dir = makeCheckpoint(run.dir, 10);
  writeText(dir / "dem.h5", "dem");
  EXPECT_NE(verifyCheckpoint(dir).find("dem.h5: size 3 bytes"), std::string::npos);
}

TEST(Checkpoint, NoCheckpointAtAll) {
  TempRun run;
  const ResumeChoice c = selectResumeCheckpoint(run.dir);
  EXPECT_FALSE(c.dir.has_value());
  EXPECT_TRUE(c.skipped.empty());
}

TEST(Checkpoint, PruneKeepsLastK) {
  TempRun run;
  for (int s : {10, 20, 30, 40}) {
    makeCheckpoint(run.dir, s);
  }
  makeCheckpoint(run.dir, 25, false); // an old incomplete one
  makeCheckpoint(run.dir, 50, false); // newer than the newest complete: left alone
  const auto removed = pruneCheckpoints(run.dir, 2);
  EXPECT_EQ(removed.size(), 3u);
  EXPECT_EQ(listCheckpointSteps(run.dir), (std::vector<std::int64_t>{30, 40, 50}));
}

TEST(Checkpoint, AtomicWriteReplaces) {
  TempRun run;
  const fs::path p = run.dir / "x.json";
  writeFileAtomic(p, "one");
  writeFileAtomic(p, "two");
  std::ifstream in(p);
  std::string s;
  in >> s;
  EXPECT_EQ(s, "two");
}

TEST(Checkpoint, DueByStepsWallTimeAndLastStep) {
  EXPECT_TRUE(checkpointDue(100, false, 50, 0.0, 0.0));
  EXPECT_FALSE(checkpointDue(101, false, 50, 0.0, 1e9));  // wall-time trigger off
  EXPECT_TRUE(checkpointDue(101, false, 50, 30.0, 30.0)); // 30 s passed
  EXPECT_FALSE(checkpointDue(101, false, 50, 30.0, 29.9));
  EXPECT_TRUE(checkpointDue(7, true, 0, 0.0, 0.0));   // the last step always
  EXPECT_FALSE(checkpointDue(7, false, 0, 0.0, 0.0)); // all off
}

TEST(Checkpoint, HexDoubleRoundTrip) {
  for (double v : {0.0, 1e-4, 0.1, -3.5e-300, 1.0 / 3.0}) {
    EXPECT_EQ(doubleFromHex(doubleToHex(v)), v);
  }
}
