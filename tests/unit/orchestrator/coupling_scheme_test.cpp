// The coupling scheme between case.yaml, Configure and StepDone (docs/coupling-schemes.md "How
// the scheme is negotiated"): a staggered case adds the Configure option coupling_scheme =
// staggered (a sequential one adds nothing); the DEM server's option mapping takes it as its own
// (not an ignored model option); the orchestrator refuses a StepDone that does not confirm the
// case's scheme, as from a server that ignored the option.
#include <filesystem>

#include <gtest/gtest.h>

#include <coredem/orchestrator/case_config.h>
#include <coredem/protocol/coupling_scheme.h>
#include <coredem/protocol/protocol.h>

#include "configure.h"
#include "configure_map.h"

using namespace coredem::orchestrator;
namespace fs = std::filesystem;
namespace v1 = coredem::v1;

namespace {

const char* kCase = R"(name: scheme
time: {end: 0.01, dt: 1.0e-4}
grid: {spacing: [0.01, 0.01, 0.01], cells: [2, 2, 4]}
materials:
  - {name: glass, density: 2500, k_n: 1000, e_n: 0.9}
particles:
  - {material: glass, count: 10, diameter: 2.0e-3, packing: random,
     region: {min: [0, 0, 0.01], max: [0.02, 0.02, 0.02]}}
walls:
  box: {min: [0, 0, 0], max: [0.02, 0.02, 0.04]}
models: {drag: gidaspow}
)";

CaseConfig parse(const std::string& text) {
  const fs::path d = fs::temp_directory_path();
  return parseCase(text, d / "case.yaml", d);
}

v1::Configure configureOf(const CaseConfig& c) {
  SubcyclePlan plan;
  plan.nSub = 10;
  plan.dtDem = 1e-5;
  return buildConfigure(c, fs::temp_directory_path(), 1e-4, plan);
}

v1::StepDone stepDone(bool lag) {
  v1::StepDone d;
  coredem::protocol::addNamedValue(d.mutable_diagnostics(), "mean_T_p", 300.0);
  if (lag) {
    coredem::protocol::addNamedValue(d.mutable_diagnostics(),
                                     std::string(coredem::protocol::fields::kCouplingLagDiagnostic),
                                     1.0);
  }
  return d;
}

} // namespace

TEST(CouplingScheme, StaggeredCaseAddsTheOptionSequentialAddsNothing) {
  const CaseConfig seq = parse(kCase);
  const CaseConfig stag = parse(std::string(kCase) + "coupling: {scheme: staggered}\n");
  EXPECT_FALSE(seq.coupling.staggered());
  EXPECT_TRUE(stag.coupling.staggered());
  EXPECT_FALSE(parse(std::string(kCase) + "coupling: {scheme: sequential}\n").coupling.staggered());
  const v1::Configure a = configureOf(seq), b = configureOf(stag);
  ASSERT_EQ(a.options_size(), 1); // drag only
  ASSERT_EQ(b.options_size(), 2);
  EXPECT_EQ(b.options(1).key(), "coupling_scheme");
  EXPECT_EQ(b.options(1).value(), "staggered");
  // The DEM server's option mapping takes it as the server's own: no "ignored option" warning.
  std::vector<std::string> ignored;
  (void)coredem::server::toDemConfig(b, &ignored);
  EXPECT_TRUE(ignored.empty());
}

TEST(CouplingScheme, UnknownSchemeNamesTheAllowedValues) {
  try {
    parse(std::string(kCase) + "coupling: {scheme: jacobi}\n");
    FAIL() << "accepted coupling.scheme jacobi";
  } catch (const CaseError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("sequential"), std::string::npos) << m;
    EXPECT_NE(m.find("staggered"), std::string::npos) << m;
  }
}

TEST(CouplingScheme, StepDoneMustConfirmTheScheme) {
  const CaseConfig seq = parse(kCase);
  const CaseConfig stag = parse(std::string(kCase) + "coupling: {scheme: staggered}\n");
  EXPECT_EQ(couplingSchemeMismatch(seq, stepDone(false), 1), "");
  EXPECT_EQ(couplingSchemeMismatch(stag, stepDone(true), 1), "");
  // A server that ignored the option (older coredem-dem) runs sequential: refused at step 1.
  const std::string old = couplingSchemeMismatch(stag, stepDone(false), 1);
  EXPECT_NE(old.find("does not run the staggered coupling scheme"), std::string::npos) << old;
  EXPECT_NE(old.find("StepDone of step 1"), std::string::npos) << old;
  const std::string odd = couplingSchemeMismatch(seq, stepDone(true), 3);
  EXPECT_NE(odd.find("coupling_lag_steps in step 3 of a sequential run"), std::string::npos) << odd;
}
