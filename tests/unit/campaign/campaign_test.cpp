// Unit tests: setCaseKey, loadSweep (grid order, explicit members, errors) and CampaignDb
// (transitions are exact: done counted once, failures up to the retry limit).
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <coredem/orchestrator/campaign.h>
#include <coredem/orchestrator/campaign_db.h>
#include <coredem/orchestrator/case_config.h>

namespace fs = std::filesystem;
using namespace coredem::orchestrator;

namespace {

const fs::path kCases = COREDEM_CAMPAIGN_CASES;

fs::path tempDir(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("coredem-campu-" + std::to_string(::getpid()) + "-" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

} // namespace

TEST(CampaignKeys, SetsNestedKeysAndListEntries) {
  const std::string base = "a:\n  b: 1\n  c: [1, 2]\nl:\n  - {x: 1}\n  - {x: 2}\n";
  std::string t = setCaseKey(base, "a.b", "5.5e-3");
  t = setCaseKey(t, "l[1].x", "7");
  t = setCaseKey(t, "a.c[0]", "[9, 8]");
  t = setCaseKey(t, "new.key", "hello");
  const YAML::Node n = YAML::Load(t);
  EXPECT_EQ(n["a"]["b"].as<std::string>(), "5.5e-3"); // the value's text is kept exactly
  EXPECT_EQ(n["l"][0]["x"].as<int>(), 1);
  EXPECT_EQ(n["l"][1]["x"].as<int>(), 7);
  EXPECT_EQ(n["a"]["c"][0][1].as<int>(), 8);
  EXPECT_EQ(n["a"]["c"][1].as<int>(), 2);
  EXPECT_EQ(n["new"]["key"].as<std::string>(), "hello");
}

TEST(CampaignKeys, BadPathsNameThePath) {
  const std::string base = "a:\n  b: 1\nl: [1, 2]\n";
  auto msg = [&](const std::string& path) {
    try {
      setCaseKey(base, path, "1");
    } catch (const CaseError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(msg("l[2]").find("'l[2]': index 2 out of range ('l' has 2 entries"), std::string::npos)
      << msg("l[2]");
  EXPECT_NE(msg("a.b.c").find("'a.b.c': 'a.b' is not a mapping"), std::string::npos)
      << msg("a.b.c");
  EXPECT_NE(msg("a[0]").find("'a[0]': 'a' is not a list"), std::string::npos) << msg("a[0]");
  EXPECT_NE(msg("a..b").find("not a case key path"), std::string::npos) << msg("a..b");
  // An index beyond a long was an internal error (std::stol); a user error naming it now.
  const std::string huge = "l[99999999999999999999999]";
  EXPECT_NE(msg(huge).find("list index 99999999999999999999999 is out of range"), std::string::npos)
      << msg(huge);
  EXPECT_NE(msg("l[1000000000]").find("is out of range"), std::string::npos);
}

TEST(CampaignSweep, GridExpandsWithTheFirstKeySlowest) {
  const Sweep sw = loadSweep(kCases / "grid4.yaml");
  EXPECT_EQ(sw.name, "e2e-grid4");
  EXPECT_EQ(sw.concurrency, 2);
  EXPECT_EQ(sw.retries, 0);
  ASSERT_EQ(sw.members.size(), 4u);
  ASSERT_EQ(sw.parameters, (std::vector<std::string>{"gas.T_g", "particles[0].diameter"}));
  const std::vector<std::pair<std::string, std::string>> expect[] = {
      {{"gas.T_g", "400.0"}, {"particles[0].diameter", "1.0e-3"}},
      {{"gas.T_g", "400.0"}, {"particles[0].diameter", "1.2e-3"}},
      {{"gas.T_g", "600.0"}, {"particles[0].diameter", "1.0e-3"}},
      {{"gas.T_g", "600.0"}, {"particles[0].diameter", "1.2e-3"}}};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(sw.members[i].values, expect[i]) << i;
    EXPECT_EQ(sw.members[i].id, "m00" + std::to_string(i));
  }
  // the resolved cases parse and carry the values
  const CaseConfig c = parseCase(sw.resolvedCases[3], "case.yaml", sw.baseCase);
  EXPECT_EQ(c.particles.at(0).diameter, 1.2e-3);
  EXPECT_EQ(YAML::Load(sw.resolvedCases[3])["gas"]["T_g"].as<double>(), 600.0);
  EXPECT_EQ(sw.plotX, "particles[0].diameter");
  EXPECT_EQ(sw.plotY, "dem.kinetic_energy_J");
  ASSERT_EQ(sw.scalars.size(), 3u);
  EXPECT_EQ(sw.scalars[2].reduce, "max");
  EXPECT_EQ(sw.scalars[2].column, "dem.kinetic_energy_J");
}

TEST(CampaignSweep, ExplicitMembers) {
  const Sweep sw = loadSweep(kCases / "failing.yaml");
  ASSERT_EQ(sw.members.size(), 4u);
  ASSERT_EQ(sw.members[2].values.size(), 2u);
  EXPECT_EQ(sw.members[2].values.at(0).first, "gas.T_g");
  EXPECT_EQ(sw.members[2].values.at(0).second, "500.0");
  EXPECT_EQ(sw.members[2].values.at(1).first, "gas.u_g[2]");
  EXPECT_EQ(sw.members[2].values.at(1).second, "-30.0");
  EXPECT_EQ(sw.retries, 2);
  EXPECT_EQ(sw.scalars.at(0).column, "mean_T_p"); // default result
}

TEST(CampaignSweep, ScalarWindowsReadAndWriteTheirLabels) {
  const ScalarSpec a = parseScalarLabel("mean@0.5..:gas.pressure_drop_Pa");
  EXPECT_EQ(a.reduce, "mean");
  EXPECT_EQ(a.column, "gas.pressure_drop_Pa");
  ASSERT_TRUE(a.from.has_value());
  EXPECT_EQ(*a.from, 0.5);
  EXPECT_FALSE(a.to.has_value());
  EXPECT_EQ(a.label(), "mean@0.5..:gas.pressure_drop_Pa");
  const ScalarSpec b = parseScalarLabel("max@..0.25:bed_height_m");
  EXPECT_EQ(*b.to, 0.25);
  EXPECT_FALSE(b.from.has_value());
  EXPECT_EQ(parseScalarLabel("min@0.1..0.2:x").label(), "min@0.1..0.2:x");
  EXPECT_EQ(parseScalarLabel("mean_T_p").label(), "mean_T_p");
  EXPECT_EQ(parseScalarLabel("max:x").baseLabel(), "max:x");
  for (const char* bad :
       {"final@0.1..:x", "mean@0.1:x", "mean@a..:x", "mean@0.2..0.1:x", "median:x", "mean:"}) {
    EXPECT_THROW(parseScalarLabel(bad), CaseError) << bad;
  }
}

TEST(CampaignSweep, MappingScalarsParamKeysAndUnits) {
  const fs::path d = tempDir("param");
  fs::create_directory_symlink(fs::absolute(kCases / "tiny"), d / "tiny");
  std::ofstream(d / "sweep.yaml") << "base_case: tiny\n"
                                     "members:\n"
                                     "  - {gas.T_g: 400.0, param.U_in: 0.1}\n"
                                     "  - {gas.T_g: 500.0, param.U_in: 0.2}\n"
                                     "collect:\n"
                                     "  scalars: [{mean: mean_T_p, from: 0.01}, "
                                     "{max: dem.kinetic_energy_J, from: 0.005, to: 0.015}]\n"
                                     "  units: {param.U_in: m/s}\n"
                                     "  plot: {x: param.U_in, y: \"mean:mean_T_p\"}\n";
  const Sweep sw = loadSweep(d / "sweep.yaml");
  ASSERT_EQ(sw.scalars.size(), 2u);
  EXPECT_EQ(sw.scalars[0].label(), "mean@0.01..:mean_T_p");
  EXPECT_EQ(sw.scalars[1].label(), "max@0.005..0.015:dem.kinetic_energy_J");
  EXPECT_EQ(sw.plotY, "mean@0.01..:mean_T_p"); // found by the label without its window
  EXPECT_EQ(sw.plotX, "param.U_in");
  ASSERT_EQ(sw.units.size(), 1u);
  EXPECT_EQ(sw.units[0], (std::pair<std::string, std::string>{"param.U_in", "m/s"}));
  // a param. key is recorded with the member but never written into its case
  EXPECT_EQ(sw.members[1].values.at(1), (std::pair<std::string, std::string>{"param.U_in", "0.2"}));
  const YAML::Node c = YAML::Load(sw.resolvedCases[1]);
  EXPECT_FALSE(c["param"]);
  EXPECT_EQ(c["gas"]["T_g"].as<double>(), 500.0);
  fs::remove_all(d);
}

TEST(CampaignDbTest, TransitionsAreCountedExactly) {
  const fs::path d = tempDir("db");
  CampaignDb db(d / "campaign.db", true);
  db.createSchema();
  MemberRecord m;
  m.id = "m000";
  m.caseDir = "c";
  m.runDir = "r";
  m.caseHash = "h";
  m.values = {{"gas.T_g", "400"}};
  db.transaction([&] { db.addMember(m); });
  EXPECT_FALSE(db.markDone("m000", "", "", "")); // not running
  EXPECT_TRUE(db.markRunning("m000", "pending"));
  EXPECT_FALSE(db.markRunning("m000", "pending")); // claimed once
  // retries = 1: the first failure goes back to pending, the second is final
  EXPECT_TRUE(db.markFailed("m000", "exited with code 1", 1));
  EXPECT_EQ(db.member("m000")->status, "pending");
  EXPECT_TRUE(db.markRunning("m000", "pending"));
  EXPECT_TRUE(db.markFailed("m000", "exited with code 1", 1));
  EXPECT_EQ(db.member("m000")->status, "failed");
  EXPECT_EQ(db.member("m000")->failures, 2);
  EXPECT_EQ(db.member("m000")->attempts, 2);
  EXPECT_TRUE(db.resetFailed("m000"));
  EXPECT_TRUE(db.markRunning("m000", "pending"));
  db.setPid("m000", 4242);
  EXPECT_EQ(db.member("m000")->pid, 4242);
  db.transaction([&] {
    EXPECT_TRUE(db.markDone("m000", "00000040", "0.1.0", "1.0"));
    db.addEvent("m000", "done", "");
  });
  EXPECT_FALSE(db.markDone("m000", "00000040", "0.1.0", "1.0")); // never twice
  const auto r = db.member("m000");
  EXPECT_EQ(r->status, "done");
  EXPECT_EQ(r->doneCount, 1);
  EXPECT_EQ(r->pid, 0);
  EXPECT_EQ(r->attempts, 3);
  EXPECT_EQ(r->protocolVersion, "1.0");
  EXPECT_EQ(db.doneEvents("m000"), 1);
  EXPECT_EQ(r->values, m.values);
  // a transaction that throws leaves nothing behind
  EXPECT_THROW(db.transaction([&] {
    db.addEvent("m000", "done", "");
    throw std::runtime_error("crash");
  }),
               std::runtime_error);
  EXPECT_EQ(db.doneEvents("m000"), 1);
  fs::remove_all(d);
}

TEST(CampaignSlurm, TimeLimitsParseAsSbatchReadsThem) {
  EXPECT_EQ(parseSlurmTime("30"), 30 * 60);             // minutes
  EXPECT_EQ(parseSlurmTime("1:30"), 90);                // minutes:seconds
  EXPECT_EQ(parseSlurmTime("2:00:00"), 7200);           // hours:minutes:seconds
  EXPECT_EQ(parseSlurmTime("1-00:00:00"), 86400);       // days-hours:minutes:seconds
  EXPECT_EQ(parseSlurmTime("1-2"), 86400 + 2 * 3600);   // days-hours
  EXPECT_EQ(parseSlurmTime("1-2:30"), 93600 + 30 * 60); // days-hours:minutes
  EXPECT_FALSE(parseSlurmTime("abc"));
  EXPECT_FALSE(parseSlurmTime("1:2:3:4"));
  EXPECT_FALSE(parseSlurmTime(""));
}

TEST(CampaignSlurm, ShippedSlurmSweepLoads) {
  const Sweep sw = loadSweep(fs::path(COREDEM_CAMPAIGN_CASES) /
                             "../../../../cases/campaign-demo/sweep-slurm.yaml");
  EXPECT_EQ(sw.executor, "slurm");
  EXPECT_EQ(sw.members.size(), 6u);
  EXPECT_EQ(sw.slurm.time, "10");
  EXPECT_EQ(sw.slurm.timeSeconds, 600);
  EXPECT_EQ(sw.slurm.cpusPerTask, 1);
  EXPECT_EQ(sw.slurm.stopMargin, 60);
  EXPECT_EQ(sw.slurm.maxConcurrent, 0); // the sweep's concurrency applies
  EXPECT_TRUE(sw.slurm.extra.empty());
}

// A grid key given twice: the sweep reader took the last, the case reader the first; refused
// with both lines, as is a second YAML document.
TEST(CampaignSweep, DuplicateKeysAndASecondDocumentAreRefused) {
  const fs::path d = tempDir("dup");
  fs::copy(kCases / "tiny", d / "tiny", fs::copy_options::recursive);
  const std::string head = "name: dup\nbase_case: tiny\ngrid:\n  gas.T_g: [400.0, 600.0]\n";
  auto error = [&](const std::string& text) -> std::string {
    std::ofstream(d / "sweep.yaml") << text;
    try {
      (void)loadSweep(d / "sweep.yaml");
    } catch (const CaseError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(error(head), "");
  const std::string twice = error(head + "  gas.T_g: [500.0]\n");
  EXPECT_NE(twice.find("sweep.yaml:5:3: gas.T_g: given twice in the same mapping (first at line "
                       "4)"),
            std::string::npos)
      << twice;
  const std::string second = error(head + "---\nname: other\n");
  EXPECT_NE(second.find("sweep.yaml:6:1: document: a second YAML document"), std::string::npos)
      << second;
  fs::remove_all(d);
}

// A member the run would refuse is refused when the sweep is loaded (issue 39 item 2): each
// member's case is pre-flighted as `coredem check` does. k_n = 2e21 N/m needs ~10^10 DEM
// sub-steps per CFD step; before, the sweep loaded and that member exited 2 at its start.
TEST(CampaignSweep, AMemberTheRunWouldRefuseIsRefusedAtLoad) {
  const fs::path d = tempDir("preflight");
  fs::copy(kCases / "tiny", d / "tiny", fs::copy_options::recursive);
  std::ofstream(d / "sweep.yaml")
      << "name: stiff\nbase_case: tiny\ngrid:\n  materials[0].k_n: [20.0, 2.0e21]\n";
  std::string e;
  try {
    (void)loadSweep(d / "sweep.yaml");
  } catch (const CaseError& err) {
    e = err.what();
  }
  EXPECT_NE(e.find("member m001 (materials[0].k_n = 2.0e21) gives an invalid case"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("DEM sub-steps"), std::string::npos) << e;
  fs::remove_all(d);
}
