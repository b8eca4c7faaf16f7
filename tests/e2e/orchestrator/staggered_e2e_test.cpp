// End-to-end tests of the staggered coupling scheme (`coupling: {scheme: staggered}`,
// docs/coupling-schemes.md) with `coredem`, the real coredem-dem and coredem-gas:
// - the heat ledgers close with the lag booked (balance.heat_residual_J at round-off) and the lag
//   is what the scheme says (the last step's particle gain less the step-1 initial sources);
// - against the sequential scheme: with a prescribed gas the particles do not feel the scheme
//   (bitwise the same DEM state), and the gas's cumulative heat differs by the lag only;
// - restart identity: 200 steps straight == 100 + resume + 100, bitwise (pending sources in the
//   DEM checkpoint);
// - mass: the species the gas receives are those D hands over, and D's in-flight species are
//   what the particles released less what the gas received.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <regex>
#include <string>

#include <gtest/gtest.h>

#include "coredem_e2e.h"
#include "coredem_e2e_hdf5.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

const fs::path kBin = COREDEM_BIN_DIR;
const fs::path kCases = COREDEM_E2E_CASES;
using coredem::e2e::readAll;
using coredem::e2e::readTimeseries;

int runCoredem(const std::vector<std::string>& args, const fs::path& log) {
  return coredem::e2e::waitExit(coredem::e2e::startProgram(kBin / "coredem", args, log), 50s);
}

class StaggeredE2E : public coredem::e2e::RunFolderTest {
protected:
  StaggeredE2E()
      : RunFolderTest(kBin, {"coredem", "coredem-dem", "coredem-gas"}, "coredem-staggered-e2e") {}
  const fs::path staggeredCase = kCases / "staggered";
  const fs::path sequentialCase = kCases / "restart"; // the same case, sequential (the default)
};

/// The DEM state file of a checkpoint folder (the one file of participant dem: dem.h5).
fs::path demState(const fs::path& run, int step) {
  char name[64];
  std::snprintf(name, sizeof name, "checkpoints/%08d/dem.h5", step);
  return run / name;
}

/// Datasets of a DEM state file under `prefix` (e.g. "particles/"), by name.
std::map<std::string, std::string> datasetsUnder(const fs::path& file, const std::string& prefix) {
  std::map<std::string, std::string> out;
  for (auto& [name, bytes] : coredem::e2e::datasetsOf(file)) {
    if (name.rfind(prefix, 0) == 0) {
      out.emplace(name, std::move(bytes));
    }
  }
  return out;
}

} // namespace

// Ledgers of a staggered run with coredem-gas (steady gas at 500 K, particles at 300 K):
// (1) balance.heat_residual_J = dem.heat_from_gas_J + gas.heat_from_particles_J −
//     dem.heat_in_flight_J closes to round-off (1e-9 of the heat exchanged so far): what the gas
//     received is what the DEM handed it;
// (2) dem.heat_in_flight_J(n) = [dem.heat_from_gas_J(n) − (n−1)] + gas.heat_from_particles_J(1):
//     the particles' gain of the last step (not yet applied by the gas) less the step-1 sources
//     of the initial state (applied by the gas, computed from no step), same tolerance.
TEST_F(StaggeredE2E, LedgersCloseWithTheLagBooked) {
  const fs::path a = dir / "run";
  ASSERT_EQ(
      runCoredem({"run", staggeredCase.string(), "--out", a.string(), "--no-plots"}, dir / "a.log"),
      0)
      << readAll(dir / "a.log");
  EXPECT_NE(readAll(a / "logs" / "dem.log").find("staggered coupling"), std::string::npos);
  auto ts = readTimeseries(a);
  const auto& hfg = ts["dem.heat_from_gas_J"];
  const auto& gas = ts["gas.heat_from_particles_J"];
  const auto& inFlight = ts["dem.heat_in_flight_J"];
  const auto& residual = ts["balance.heat_residual_J"];
  ASSERT_EQ(hfg.size(), 200u);
  ASSERT_EQ(inFlight.size(), 200u);
  ASSERT_EQ(residual.size(), 200u);
  ASSERT_GT(hfg.back(), 1e-3) << "the case must exchange heat";
  ASSERT_LT(gas.front(), 0.0) << "step 1: the gas gives heat to the particles (initial sources)";
  for (double lag : ts["coupling_lag_steps"]) {
    ASSERT_EQ(lag, 1.0);
  }
  for (std::size_t i = 0; i < hfg.size(); ++i) {
    const double tol = 1e-9 * std::abs(hfg[i]) + 1e-15;
    EXPECT_NEAR(residual[i], 0.0, tol) << "row " << i;
    if (i > 0) {
      EXPECT_NEAR(inFlight[i], (hfg[i] - hfg[i - 1]) + gas.front(), tol) << "row " << i;
    }
  }
}

// Staggered vs sequential on the same case. With a prescribed gas the gas does not respond to the
// sources, so the particles move and heat exactly alike (bitwise the same DEM state after 200
// steps), and the only difference is when the gas receives the heat: one step later, starting
// with the initial sources. The gas's cumulative heat therefore differs by at most one step's
// transfer at each end: |gas_stag(n) − gas_seq(n)| <= |Δ dem.heat_from_gas_J(n)| + |gas_stag(1)|
// (+ round-off), at every step; and the difference is not zero (the lag is real).
TEST_F(StaggeredE2E, DiffersFromSequentialByTheOneStepLagOnly) {
  const fs::path s = dir / "sequential", g = dir / "staggered";
  ASSERT_EQ(runCoredem({"run", sequentialCase.string(), "--out", s.string(), "--no-plots"},
                       dir / "s.log"),
            0)
      << readAll(dir / "s.log");
  ASSERT_EQ(
      runCoredem({"run", staggeredCase.string(), "--out", g.string(), "--no-plots"}, dir / "g.log"),
      0)
      << readAll(dir / "g.log");
  for (const char* prefix : {"particles/", "contacts/"}) {
    const auto ds = datasetsUnder(demState(s, 200), prefix);
    const auto dg = datasetsUnder(demState(g, 200), prefix);
    ASSERT_FALSE(ds.empty());
    EXPECT_TRUE(ds == dg) << prefix << " datasets differ between the schemes";
  }
  auto ts = readTimeseries(s), tg = readTimeseries(g);
  EXPECT_EQ(ts.count("coupling_lag_steps"), 0u) << "a sequential run reports no lag";
  const auto& hfg = tg["dem.heat_from_gas_J"];
  ASSERT_EQ(ts["dem.heat_from_gas_J"], hfg); // the particles' side is the same
  const auto& gs = ts["gas.heat_from_particles_J"];
  const auto& gg = tg["gas.heat_from_particles_J"];
  ASSERT_EQ(gs.size(), 200u);
  ASSERT_EQ(gg.size(), 200u);
  double largest = 0.0;
  for (std::size_t i = 1; i < gs.size(); ++i) {
    const double bound = (std::abs(hfg[i] - hfg[i - 1]) + std::abs(gg.front())) * (1 + 1e-9);
    EXPECT_LE(std::abs(gg[i] - gs[i]), bound) << "row " << i;
    largest = std::max(largest, std::abs(gg[i] - gs[i]));
  }
  EXPECT_GT(largest, 0.0);
}

// 200 steps straight vs 100 + resume + 100: the resumed run starts with the pending sources of
// the checkpoint, so the DEM state (particles, contacts, pending sources and lag ledgers) and
// every ledger of the timeseries are bitwise those of the straight run.
TEST_F(StaggeredE2E, RestartIdentity) {
  const fs::path a = dir / "straight", b = dir / "split";
  ASSERT_EQ(
      runCoredem({"run", staggeredCase.string(), "--out", a.string(), "--no-plots"}, dir / "a.log"),
      0)
      << readAll(dir / "a.log");
  ASSERT_EQ(runCoredem({"run", staggeredCase.string(), "--out", b.string(), "--stop-after", "100",
                        "--no-plots"},
                       dir / "b1.log"),
            0)
      << readAll(dir / "b1.log");
  ASSERT_EQ(runCoredem({"resume", b.string(), "--no-plots"}, dir / "b2.log"), 0)
      << readAll(dir / "b2.log");
  for (const char* prefix : {"particles/", "contacts/", "server/staggered/"}) {
    const auto da = datasetsUnder(demState(a, 200), prefix);
    const auto db = datasetsUnder(demState(b, 200), prefix);
    ASSERT_FALSE(da.empty()) << prefix;
    EXPECT_TRUE(da == db) << prefix << " datasets differ between the straight and resumed runs";
  }
  auto ta = readTimeseries(a), tb = readTimeseries(b);
  for (const char* column : {"dem.heat_from_gas_J", "dem.heat_in_flight_J",
                             "gas.heat_from_particles_J", "balance.heat_residual_J", "mean_T_p"}) {
    EXPECT_EQ(ta[column], tb[column]) << column;
  }
}

// Mass transfer with the lag (case staggered-chemistry: 27 held beads convert solid B into gas C
// at a constant rate until B runs out at t ~ 22 ms; Δt_CFD grows from 0.5 to 2 ms). Per step and
// species C:
// (1) dem.species_to_gas (booked by D when it sends the sources) = gas.species (booked by the gas
//     when it applies them);
// (2) dem.solid_to_gas (released by the particles, booked in the step that computes it) −
//     dem.species_to_gas = dem.species_in_flight;
// (3) after B is gone the last step released nothing, so what stays in flight is minus the
//     step-1 initial sources' transfer: −gas.species(1). With a growing Δt this holds only
//     because D rescales the lagged R_species to the Δt that applies them.
// Tolerance 1e-12 of the mass released (sums of a few tens of terms).
TEST_F(StaggeredE2E, SpeciesLedgersCloseWithTheLagBooked) {
  const fs::path a = dir / "run";
  ASSERT_EQ(runCoredem({"run", (kCases / "staggered-chemistry").string(), "--out", a.string(),
                        "--no-plots"},
                       dir / "a.log"),
            0)
      << readAll(dir / "a.log");
  auto ts = readTimeseries(a);
  const auto& dt = ts["dt"];
  const auto& toGas = ts["dem.species_to_gas.C_kg"];
  const auto& gas = ts["gas.species.C_kg"];
  const auto& solid = ts["dem.solid_to_gas.C_kg"];
  const auto& inFlight = ts["dem.species_in_flight.C_kg"];
  const std::size_t n = toGas.size();
  ASSERT_GE(n, 20u);
  ASSERT_EQ(inFlight.size(), n);
  ASSERT_GT(dt[5], 1.5 * dt[0]) << "the test needs a varying Δt";
  ASSERT_GT(gas.front(), 0.0);
  ASSERT_EQ(solid[n - 1], solid[n - 3]) << "B must run out during the run (the test needs it)";
  for (std::size_t i = 0; i < n; ++i) {
    const double tol = 1e-12 * solid[i];
    EXPECT_NEAR(toGas[i], gas[i], tol) << "row " << i;
    EXPECT_NEAR(solid[i] - toGas[i], inFlight[i], tol) << "row " << i;
  }
  EXPECT_NEAR(inFlight.back(), -gas.front(), 1e-12 * solid.back());
}
