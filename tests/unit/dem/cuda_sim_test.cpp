// The cuda-sim backend's memory model (backend/cuda_sim/cuda_sim_exec.h): what makes a missing
// host↔device synchronisation visible without a GPU.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "backend/arrays.h"
#include "backend/cuda_sim/cuda_sim_exec.h"
#include "coredem/dem/dem_system.h"

using namespace coredem::dem::backend;

namespace {
using Exec = CudaSimExec;
template <class T>
using Dual = DualArray<T, Exec>;

/// Copies n values of a device array to a host vector (as the engine does).
template <class T>
std::vector<T> fromDevice(const T* d, std::size_t n) {
  std::vector<T> out(n);
  Exec::copyToHost(out.data(), d, n * sizeof(T));
  return out;
}
} // namespace

TEST(CudaSim, FreshDeviceAndHostMemoryIsGarbageNotZero) {
  Dual<double> a;
  a.allocate(100);
  for (std::size_t k = 0; k < 100; ++k)
    EXPECT_TRUE(std::isnan(a.h()[k])) << k; // host mirror: signalling NaN pattern
  for (double v : fromDevice(a.d(), 100))
    EXPECT_TRUE(std::isnan(v));
  Dual<std::int32_t> b;
  b.allocate(10);
  for (std::int32_t v : fromDevice(b.d(), 10))
    EXPECT_NE(v, 0);
  EXPECT_NE(static_cast<const void*>(a.h()), static_cast<const void*>(a.d()));
}

TEST(CudaSim, CopiesFollowTheModifySyncFlagsOnly) {
  Exec exec;
  Dual<double> a;
  a.allocate(1000);
  for (std::size_t k = 0; k < 1000; ++k)
    a.h()[k] = static_cast<double>(k);
  a.toDevice(); // not marked: nothing moves, the device keeps its garbage
  EXPECT_TRUE(std::isnan(fromDevice(a.d(), 1000)[7]));
  a.markHostModified();
  a.toDevice();
  EXPECT_EQ(fromDevice(a.d(), 1000)[7], 7.0);
  double* d = a.d();
  exec.parallelFor(1000, [=](std::size_t i) { d[i] *= 2.0; });
  a.toHost(); // the kernel's write was not marked: the host mirror is stale
  EXPECT_EQ(a.h()[7], 7.0);
  a.markDeviceModified();
  a.toHost();
  EXPECT_EQ(a.h()[7], 14.0);
}

TEST(CudaSim, PrimitivesMatchTheCpuBackend) {
  Exec sim;
  CpuExec cpu;
  const std::size_t n = 5003;
  std::vector<std::uint32_t> keys(n);
  std::uint64_t s = 7;
  for (auto& k : keys) {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    k = static_cast<std::uint32_t>((s >> 33) % 300);
  }
  auto* dk = static_cast<std::uint32_t*>(Exec::allocDevice(n * 4));
  auto* dp = static_cast<std::uint32_t*>(Exec::allocDevice(n * 4));
  Exec::copyToDevice(dk, keys.data(), n * 4);
  sim.sortByKey(dk, n, 300, dp);
  std::vector<std::uint32_t> ref(n);
  cpu.sortByKey(keys.data(), n, 300, ref.data());
  EXPECT_EQ(fromDevice(dp, n), ref); // stable: the one permutation
  std::vector<std::uint32_t> scanRef(n);
  cpu.exclusiveScan(keys.data(), scanRef.data(), n);
  sim.exclusiveScan(dk, dp, n);
  EXPECT_EQ(fromDevice(dp, n), scanRef);
  const std::uint32_t* k = dk;
  EXPECT_EQ(sim.reduceMax(
                n, [=](std::size_t i) { return static_cast<double>(k[i]); }, -1.0),
            299.0);
  EXPECT_EQ(sim.reduceMax(
                n, [=](std::size_t i) { return static_cast<double>(k[i]); }, 1e3),
            1e3);
  Exec::freeDevice(dk);
  Exec::freeDevice(dp);
}

TEST(CudaSimDeathTest, HostCodeDereferencingADevicePointerStops) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  Dual<double> a;
  a.allocate(16);
  volatile double* d = a.d();
  EXPECT_DEATH({ d[3] = 1.0; }, "cuda-sim: SIGSEGV");
  // Inside a kernel it is fine.
  Exec exec;
  double* dd = a.d();
  exec.parallelFor(16, [=](std::size_t i) { dd[i] = 1.0; });
  EXPECT_EQ(fromDevice(a.d(), 16)[3], 1.0);
}

namespace {
coredem::dem::DemConfig fourParticles(bool chemistry) {
  using namespace coredem::dem;
  DemConfig c;
  c.gravity = {0, 0, 0};
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.positions = {0, 0, 0, 2e-3, 0, 0, 0, 2e-3, 0, 0, 0, 2e-3};
  if (chemistry) {
    c.gasSpecies = {{"G", 0.015}};
    c.solidSpecies = {{"B", 0.015}, {"I", 0.020}};
    s.composition = {0.5, 0.5};
    ReactionConfig r;
    r.name = "burn";
    r.terms = {{"B", -1}, {"G", 1}};
    r.A = 1e-9;
    c.chemistry.reactions.push_back(r);
  }
  c.particleSets.push_back(s);
  return c;
}
} // namespace

// Host round trips and device synchronisations per sub-step (what coredem-bench dem reports):
// counted by the device backends only; the figures are recorded in the test's XML output.
TEST(CudaSim, HostRoundTripsAndSynchronisationsPerSubStepAreCounted) {
  using namespace coredem::dem;
  for (bool chemistry : {false, true}) {
    SCOPED_TRACE(chemistry ? "with chemistry" : "mechanics");
    DemSystem cpu(fourParticles(chemistry), BackendKind::Cpu, 1);
    DemSystem sim(fourParticles(chemistry), BackendKind::CudaSim, 1);
    const double dt = sim.dtDemMax();
    cpu.advance(dt, 1); // first sub-step: neighbour lists built
    sim.advance(dt, 1);
    const BackendSyncCounts c0 = backendSyncCounts();
    cpu.advance(100 * dt, 100);
    const BackendSyncCounts c1 = backendSyncCounts();
    EXPECT_EQ(c1.hostRoundTrips, c0.hostRoundTrips); // the cpu backend counts nothing
    EXPECT_EQ(c1.deviceSyncs, c0.deviceSyncs);
    sim.advance(100 * dt, 100);
    const BackendSyncCounts c2 = backendSyncCounts();
    EXPECT_EQ(sim.stageTimes().rebuilds, 1u); // no rebuild in the counted steps
    const double trips = static_cast<double>(c2.hostRoundTrips - c1.hostRoundTrips) / 100.0;
    const double syncs = static_cast<double>(c2.deviceSyncs - c1.deviceSyncs) / 100.0;
    const double launches = static_cast<double>(c2.launches - c1.launches) / 100.0;
    RecordProperty(chemistry ? "round_trips_per_substep_chemistry" : "round_trips_per_substep",
                   std::to_string(trips));
    std::printf("per sub-step (%s): %.2f host round trips, %.2f device syncs, %.2f launches\n",
                chemistry ? "chemistry" : "mechanics", trips, syncs, launches);
    // One status read per sub-step (the displacement maximum for the rebuild decision, the
    // contact module's slot counts, chemistry's removal flag, all left on the device) and no
    // explicit synchronisation (stage timers are events); the window's reads happen once per
    // window (0.01 per sub-step here). Before the status array: 3 (4 with chemistry) round
    // trips and 4 syncs.
    EXPECT_DOUBLE_EQ(trips, chemistry ? 1.01 : 1.0);
    EXPECT_EQ(syncs, 0.0);
    EXPECT_GT(launches, 1.0);
  }
}

// The same on a coupling grid with drag, PCM deposition and every heat term (particles held in
// place so that no neighbour rebuild falls into the counted sub-steps): one round trip per
// sub-step, whatever the modules.
TEST(CudaSim, OneHostRoundTripPerSubStepWithDragAndHeat) {
  using namespace coredem::dem;
  DemConfig c = fourParticles(false);
  c.gravity = {0, 0, -9.81};
  c.frozenMotion = true;
  c.grid.origin = {-1e-3, -1e-3, -1e-3};
  c.grid.spacing = {2e-3, 2e-3, 2e-3};
  c.grid.counts = {2, 2, 2};
  c.materials.resize(1);
  c.materials[0].emissivity = 0.9;
  c.wallTemperature = 400.0;
  c.addBox({-1e-3, -1e-3, -1e-3}, {3e-3, 3e-3, 3e-3});
  std::vector<double> u, gp, T, rho, mu, kappa, cp;
  for (int k = 0; k < 8; ++k) {
    u.insert(u.end(), {0.0, 0.0, 0.5});
    gp.insert(gp.end(), {0.0, 0.0, -2.0});
    T.push_back(350.0);
    rho.push_back(1.1);
    mu.push_back(2e-5);
    kappa.push_back(0.03);
    cp.push_back(1100.0);
  }
  DemSystem sim(c, BackendKind::CudaSim, 1);
  const GasFieldsView gas{u, gp, T, rho, mu, kappa, cp, {}, {}, {}};
  sim.setGasFields(gas);
  const double dt = 1e-5; // frozen: no contact time step limit (dtDemMax is infinite)
  sim.advance(dt, 1);
  sim.setGasFields(gas);
  const BackendSyncCounts c0 = backendSyncCounts();
  sim.advance(100 * dt, 100);
  const BackendSyncCounts c1 = backendSyncCounts();
  EXPECT_EQ(sim.stageTimes().rebuilds, 1u);
  const double trips = static_cast<double>(c1.hostRoundTrips - c0.hostRoundTrips);
  const double syncs = static_cast<double>(c1.deviceSyncs - c0.deviceSyncs);
  std::printf("100 coupled sub-steps: %.0f host round trips, %.0f device syncs\n", trips, syncs);
  // 100 status reads; the window adds its gas-field upload checks and source reads (a few).
  EXPECT_GE(trips, 100.0);
  EXPECT_LE(trips, 110.0);
  EXPECT_LE(syncs, 2.0);                       // the window start's ε_g freeze
  EXPECT_GT(sim.heatTotals().convection, 0.0); // the heat stages really ran
}
