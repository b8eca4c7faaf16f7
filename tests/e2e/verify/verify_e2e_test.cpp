// End-to-end tests of `coredem verify` (docs/verification.md) with the real coredem-dem and
// coredem-gas. The full suite takes about 10 minutes on 2 cores, so the pass test runs one
// case per family copied from cases/verification with a shorter end time (the tolerances,
// geometry, properties and steps are those of the committed cases); the fail test gives the
// contact case a tolerance it cannot meet (1e-12) in a test-only folder.
#include <chrono>
#include <regex>
#include <string>

#include "coredem_e2e.h"

namespace {

using namespace std::chrono_literals;
using coredem::e2e::readAll;
using coredem::e2e::writeAll;
namespace fs = std::filesystem;

const fs::path kBin = COREDEM_BIN_DIR;
const fs::path kCases = COREDEM_VERIFY_CASES;

class VerifyE2E : public coredem::e2e::RunFolderTest {
protected:
  VerifyE2E()
      : RunFolderTest(kBin, {"coredem", "coredem-dem", "coredem-gas"}, "verify-e2e") {}

  /// Copies cases/verification/<name> to dir/cases/<name>, with `end` as time.end (and
  /// replacements in verify.yaml).
  void copyCase(const std::string& name, const std::string& end, const std::string& verifyFrom = "",
                const std::string& verifyTo = "") {
    const fs::path to = dir / "cases" / name;
    fs::create_directories(to);
    std::string c = readAll(kCases / name / "case.yaml");
    c = std::regex_replace(c, std::regex("\n  end: [0-9.e+-]+\n"), "\n  end: " + end + "\n");
    writeAll(to / "case.yaml", c);
    std::string v = readAll(kCases / name / "verify.yaml");
    if (!verifyFrom.empty()) {
      const auto pos = v.find(verifyFrom);
      ASSERT_NE(pos, std::string::npos) << verifyFrom;
      v.replace(pos, verifyFrom.size(), verifyTo);
    }
    writeAll(to / "verify.yaml", v);
  }

  int verify(const std::vector<std::string>& args, std::chrono::seconds timeout) {
    std::vector<std::string> a = {"verify"};
    a.insert(a.end(), args.begin(), args.end());
    return coredem::e2e::waitExit(coredem::e2e::startProgram(kBin / "coredem", a, dir / "v.log"),
                                  timeout);
  }

  /// The summary entries of `name` as "metric|pass" strings (the file is our own JSON).
  static std::vector<std::pair<std::string, bool>> entries(const std::string& json,
                                                           const std::string& name) {
    std::vector<std::pair<std::string, bool>> out;
    const std::regex e("\\{\"name\":\"" + name +
                       "\",\"metric\":\"([^\"]*)\",\"value\":([^,]*),\"tolerance\":([^,]*),"
                       "\"pass\":(true|false)\\}");
    for (std::sregex_iterator it(json.begin(), json.end(), e), end; it != end; ++it) {
      out.emplace_back((*it)[1].str(), (*it)[4].str() == "true");
    }
    return out;
  }
};

} // namespace

TEST_F(VerifyE2E, OneCasePerFamilyPasses) {
  copyCase("contact-d36-overlap4e-5", "10.0");      // 1e5 sub-steps, tolerance 6e-6
  copyCase("lens-touching-smin4e-10", "5.0");       // 2.5e5 sub-steps, tolerance 1.5e-6
  copyCase("mfix-convection-ranz-marshall", "2.0"); // 2e5 sub-steps, tolerance 1e-6
  copyCase("mfix-radiation", "20.0");               // 4e5 sub-steps, tolerance 2e-7 vs RK4
  copyCase("mfix-reactive-chemistry", "2.0");       // as committed: B runs out at 1.5 s
  const int rc =
      verify({"--cases", (dir / "cases").string(), "--out", (dir / "out").string()}, 240s);
  const std::string log = readAll(dir / "v.log");
  ASSERT_EQ(rc, 0) << log;
  const std::string json = readAll(dir / "out" / "summary.json");
  EXPECT_NE(json.find("\"all_pass\":true"), std::string::npos) << json;
  for (const char* name : {"contact-d36-overlap4e-5", "lens-touching-smin4e-10"}) {
    const auto e = entries(json, name);
    ASSERT_EQ(e.size(), 2u) << name << "\n" << json; // temperatures + energy drift
    EXPECT_TRUE(e[0].second && e[1].second) << name;
    EXPECT_NE(e[1].first.find("energy"), std::string::npos);
  }
  {
    const auto e = entries(json, "mfix-reactive-chemistry");
    ASSERT_EQ(e.size(), 2u) << json; // particle mass + mass fractions
    EXPECT_TRUE(e[0].second && e[1].second);
    EXPECT_NE(e[1].first.find("mass fractions"), std::string::npos);
  }
  for (const char* name : {"mfix-convection-ranz-marshall", "mfix-radiation"}) {
    const auto e = entries(json, name);
    ASSERT_EQ(e.size(), 1u) << name << "\n" << json;
    EXPECT_TRUE(e[0].second) << name;
  }
  // Per-case series at full precision and one plot per family.
  const std::string csv = readAll(dir / "out" / "mfix-radiation" / "verify.csv");
  EXPECT_EQ(csv.rfind("# case=mfix-radiation;family=radiation;", 0), 0u) << csv.substr(0, 80);
  EXPECT_NE(csv.find("t,sim:T1,ref:T1,sim:T2,ref:T2,error"), std::string::npos);
  for (const char* family :
       {"contact-conduction", "gas-lens", "convection", "radiation", "reaction"}) {
    EXPECT_TRUE(fs::exists(dir / "out" / "plots" / (std::string(family) + ".png")))
        << family << "\n"
        << readAll(dir / "out" / "plot.log");
  }
  // The table: 2 + 2 + 1 + 1 + 2 comparisons.
  EXPECT_NE(log.find("8 comparisons, all pass; 0 skipped"), std::string::npos) << log;
}

TEST_F(VerifyE2E, FailedComparisonExitsNonZero) {
  copyCase("contact-d36-overlap4e-5", "2.0", "tolerance: 6.0e-6", "tolerance: 1.0e-12");
  const int rc = verify(
      {"--cases", (dir / "cases").string(), "--out", (dir / "out").string(), "--no-plots"}, 120s);
  const std::string log = readAll(dir / "v.log");
  EXPECT_EQ(rc, 1) << log;
  const std::string json = readAll(dir / "out" / "summary.json");
  EXPECT_NE(json.find("\"all_pass\":false"), std::string::npos) << json;
  const auto e = entries(json, "contact-d36-overlap4e-5");
  ASSERT_EQ(e.size(), 2u) << json;
  EXPECT_FALSE(e[0].second); // the temperatures miss 1e-12
  EXPECT_TRUE(e[1].second);  // the energy still holds
  EXPECT_NE(log.find("FAIL"), std::string::npos) << log;
}

TEST_F(VerifyE2E, ListAndBadNames) {
  EXPECT_EQ(verify({"--list"}, 30s), 0);
  const std::string list = readAll(dir / "v.log");
  for (const char* name :
       {"mfix-contact-conduction", "mfix-gas-lens", "mfix-convection-ranz-marshall",
        "convection-li-mason-0.6ms", "mfix-radiation", "mfix-reactive-chemistry"}) {
    EXPECT_NE(list.find(name), std::string::npos) << name << "\n" << list;
  }
  fs::remove(dir / "v.log");
  EXPECT_EQ(verify({"--only", "no-such-case", "--out", (dir / "out").string()}, 30s), 2);
  EXPECT_NE(readAll(dir / "v.log").find("no such verification case"), std::string::npos)
      << readAll(dir / "v.log");
}

TEST_F(VerifyE2E, ForcedDemStepAboveTheStableStepIsRefused) {
  // The contact pair without `motion: frozen`: t_col/50 = 8.6e-7 s, far below dt_dem = 1e-4 s.
  copyCase("contact-d36-overlap4e-5", "1.0");
  const fs::path c = dir / "cases" / "contact-d36-overlap4e-5" / "case.yaml";
  std::string text = readAll(c);
  const auto pos = text.find("motion: frozen, ");
  ASSERT_NE(pos, std::string::npos);
  writeAll(c, text.erase(pos, std::string("motion: frozen, ").size()));
  const int rc =
      coredem::e2e::waitExit(coredem::e2e::startProgram(kBin / "coredem",
                                                        {"run", c.parent_path().string(), "--out",
                                                         (dir / "run").string(), "--no-plots"},
                                                        dir / "r.log"),
                             60s);
  const std::string log = readAll(dir / "r.log");
  EXPECT_EQ(rc, 2) << log;
  EXPECT_NE(log.find("time.dt_dem = 0.0001 s exceeds the DEM server's stable step"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("models: {motion: frozen}"), std::string::npos) << log;
  // every lever is named (issue 41): the forced step, dt_factor, the stiffness / contact law
  for (const char* lever : {"time.dt_dem <=", "dem.dt_factor", "materials[].k_n", "contact law"}) {
    EXPECT_NE(log.find(lever), std::string::npos) << lever << "\n" << log;
  }
}
