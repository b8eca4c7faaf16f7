// Unit tests of coredem-gas's prescribed gas model (docs/client.md, "coredem-gas input").
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "coredem/common/check.h"
#include "coredem/gas/gas_model.h"

using coredem::UserError;
using coredem::gas::CartesianGrid;
using coredem::gas::GasFieldArrays;
using coredem::gas::GasModel;

namespace {

CartesianGrid grid4x2x2() {
  CartesianGrid g;
  g.origin = {0.0, 0.0, 0.0};
  g.spacing = {0.01, 0.01, 0.01};
  g.counts = {4, 2, 2};
  return g;
}

GasModel load(const std::string& text) {
  return GasModel::fromYaml(YAML::Load(text), "case.yaml");
}

/// The message of the UserError thrown by f (empty when nothing is thrown).
template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const UserError& e) {
    return e.what();
  }
  return {};
}

} // namespace

TEST(GasModel, DefaultsAreAirAtRestEverywhere) {
  auto m = load("{}");
  m.bind(grid4x2x2(), {});
  GasFieldArrays f;
  m.evaluate(0.0, f);
  ASSERT_EQ(f.u_g.size(), 16u * 3u);
  ASSERT_EQ(f.T_g.size(), 16u);
  EXPECT_TRUE(f.Y_g.empty());
  for (std::size_t c = 0; c < 16; ++c) {
    EXPECT_EQ(f.T_g[c], 293.15);
    EXPECT_EQ(f.rho_g[c], 1.204);
    EXPECT_EQ(f.mu_g[c], 1.81e-5);
    EXPECT_EQ(f.kappa_g[c], 0.0257);
    EXPECT_EQ(f.cp_g[c], 1005.0);
    EXPECT_EQ(f.u_g[3 * c + 2], 0.0);
    EXPECT_EQ(f.grad_p[3 * c], 0.0);
  }
}

TEST(GasModel, RegionsOverrideFieldByFieldLastWins) {
  auto m = load(R"(
T_g: 500
u_g: [0, 0, 0.3]
Y_g: {N2: 1.0}
regions:
  - name: left
    box: {min: [0, 0, 0], max: [0.02, 0.02, 0.02]}
    T_g: 300
    Y_g: {CO2: 0.25, N2: 0.75}
  - name: corner
    box: {min: [0, 0, 0], max: [0.01, 0.01, 0.01]}
    u_g: [1, 2, 3]
)");
  m.bind(grid4x2x2(), {"CO2", "N2"});
  GasFieldArrays f;
  m.evaluate(0.0, f);
  // Cell (0,0,0) = index 0: T_g from 'left', u_g from 'corner'.
  EXPECT_EQ(f.T_g[0], 300.0);
  EXPECT_EQ(f.u_g[0], 1.0);
  EXPECT_EQ(f.u_g[2], 3.0);
  EXPECT_EQ(f.Y_g[0], 0.25);
  EXPECT_EQ(f.Y_g[1], 0.75);
  // Cell (1,1,1) = 1 + 4*(1 + 2*1) = 13: centre (0.015, 0.015, 0.015), inside 'left' only.
  EXPECT_EQ(f.T_g[13], 300.0);
  EXPECT_EQ(f.u_g[13 * 3 + 2], 0.3);
  // Cell (2,0,0) = 2: centre x = 0.025, outside every region.
  EXPECT_EQ(f.T_g[2], 500.0);
  EXPECT_EQ(f.Y_g[2 * 2 + 0], 0.0);
  EXPECT_EQ(f.Y_g[2 * 2 + 1], 1.0);
}

TEST(GasModel, TimeTablesArePiecewiseLinearAndHeldOutside) {
  auto m = load(R"(
T_g: {table: [[0.1, 300.0], [0.5, 1100.0], [1.0, 1000.0]]}
u_g: {table: [[0.0, [0, 0, 0]], [0.2, [0, 0, 0.5]]]}
)");
  m.bind(grid4x2x2(), {});
  GasFieldArrays f;
  m.evaluate(0.0, f);
  EXPECT_EQ(f.T_g[5], 300.0); // before the first point: held
  m.evaluate(0.3, f);
  // 300 + (1100 - 300) * (0.3 - 0.1) / 0.4 = 700; a few ulps from the arithmetic.
  EXPECT_NEAR(f.T_g[5], 700.0, 1e-12 * 700.0);
  EXPECT_NEAR(f.u_g[5 * 3 + 2], 0.5, 1e-15);
  m.evaluate(0.75, f);
  EXPECT_NEAR(f.T_g[0], 1050.0, 1e-12 * 1050.0);
  m.evaluate(7.0, f);
  EXPECT_EQ(f.T_g[15], 1000.0); // after the last point: held
}

TEST(GasModel, UnknownKeyNamesLineKeyAndAllowedKeys) {
  const auto msg = errorOf([] { load("T_g: 300\nT_gas: 400\n"); });
  EXPECT_NE(msg.find("case.yaml:2"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'T_gas'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("kappa_g"), std::string::npos) << msg;
}

TEST(GasModel, RejectsBadValues) {
  EXPECT_NE(errorOf([] { load("T_g: -3"); }).find("must be > 0"), std::string::npos);
  EXPECT_NE(errorOf([] { load("T_g: hot"); }).find("'hot' is not a number"), std::string::npos);
  EXPECT_NE(errorOf([] { load("u_g: [1, 2]"); }).find("3-vector"), std::string::npos);
  EXPECT_NE(
      errorOf([] { load("T_g: {table: [[0.5, 300], [0.5, 400]]}"); }).find("strictly increasing"),
      std::string::npos);
  EXPECT_NE(errorOf([] { load("T_g: {tabel: [[0, 300]]}"); }).find("tabel"), std::string::npos);
  EXPECT_NE(errorOf([] { load("regions: [{T_g: 300}]"); }).find("has no 'box"), std::string::npos);
  EXPECT_NE(errorOf([] {
              load("regions: [{box: {min: [0,0,0], max: [1,0,1]}}]");
            }).find("min must be < max"),
            std::string::npos);
  EXPECT_NE(errorOf([] { load("mu_g: .nan"); }).find("not finite"), std::string::npos);
}

TEST(GasModel, CompositionMustSumToOneAtEveryBreakpoint) {
  EXPECT_NE(errorOf([] { load("Y_g: {N2: 0.7, O2: 0.2}"); }).find("sum to 0.9"), std::string::npos);
  // Each table sums to 1 at t = 0 and t = 1 only if both share breakpoints; here O2 has an extra
  // breakpoint at 0.5 where the sum is 0.5 + 0.6 = 1.1.
  const auto msg = errorOf([] {
    load("Y_g: {N2: {table: [[0, 1.0], [1, 0.0]]}, O2: {table: [[0, 0.0], [0.5, 0.6], [1, 1.0]]}}");
  });
  EXPECT_NE(msg.find("t = 0.5"), std::string::npos) << msg;
  // Complementary linear tables are valid at every t.
  auto m = load("Y_g: {N2: {table: [[0, 1.0], [1, 0.0]]}, O2: {table: [[0, 0.0], [1, 1.0]]}}");
  m.bind(grid4x2x2(), {"N2", "O2"});
  GasFieldArrays f;
  m.evaluate(0.25, f);
  EXPECT_NEAR(f.Y_g[0] + f.Y_g[1], 1.0, 1e-15);
  EXPECT_NEAR(f.Y_g[1], 0.25, 1e-15);
}

TEST(GasModel, SpeciesMustBeInTheCaseList) {
  auto m =
      load("Y_g: {N2: 1.0}\nregions: [{name: r, box: {min: [0,0,0], max: [1,1,1]}, Y_g: {XX: 1}}]");
  const auto msg = errorOf([&] { m.bind(grid4x2x2(), {"N2", "CO"}); });
  EXPECT_NE(msg.find("region 'r'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'XX'"), std::string::npos) << msg;
  auto noY = load("T_g: 300");
  EXPECT_NE(errorOf([&] { noY.bind(grid4x2x2(), {"N2"}); }).find("no Y_g is given"),
            std::string::npos);
}

TEST(GasModel, FromFileWithNestedKey) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("coredem-gas-model-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto file = (dir / "case.yaml").string();
  {
    std::ofstream out(file);
    out << "participants:\n  cfd:\n    gas:\n      T_g: 1000\n";
  }
  auto m = GasModel::fromFile(file, "participants.cfd.gas");
  m.bind(grid4x2x2(), {});
  GasFieldArrays f;
  m.evaluate(0.0, f);
  EXPECT_EQ(f.T_g[3], 1000.0);
  const auto msg = errorOf([&] { GasModel::fromFile(file, "participants.dem.gas"); });
  EXPECT_NE(msg.find("participants.dem"), std::string::npos) << msg;
  EXPECT_NE(errorOf([&] { GasModel::fromFile((dir / "nope.yaml").string()); }).find("cannot read"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}
