// Bitwise reproducibility: repeated runs, thread counts, HDF5 restart.
#include <filesystem>

#include <gtest/gtest.h>
#include <unistd.h>

#include "dem_test_util.h"

using namespace coredem::dem;
using namespace coredem::dem::testing;

namespace {
DemConfig mixedDeck() {
  // agitated particles in a box with gravity and gas drag: exercises every force path.
  DemConfig c = agitatedDeck(729, true, 11);
  c.gravity = {0, 0, -9.81};
  const auto& p = c.particleSets[0];
  c.grid.counts = {3, 3, 3};
  for (int d = 0; d < 3; ++d)
    c.grid.spacing[d] = p.regionMax[d] / 3;
  return c;
}

void setGas(DemSystem& sys) {
  const std::size_t nc = sys.cellCount();
  std::vector<double> ug(3 * nc), gp(3 * nc, 0.0), rho(nc, 1.2), mu(nc, 1.8e-5);
  for (std::size_t k = 0; k < nc; ++k) {
    ug[3 * k] = 0.1 * std::sin(0.3 * k);
    ug[3 * k + 2] = 0.8;
    gp[3 * k + 2] = -11.8;
  }
  sys.setGasFields(GasFieldsView{ug, gp, {}, rho, mu, {}, {}, {}, {}, {}});
}

void run(DemSystem& sys, int windows, std::vector<double>* lastSources = nullptr) {
  const double dt = sys.dtDemMax();
  for (int k = 0; k < windows; ++k) {
    const CellSources& s = sys.advance(25 * dt, 25);
    if (lastSources) {
      *lastSources = s.epsG;
      lastSources->insert(lastSources->end(), s.kSl.begin(), s.kSl.end());
      lastSources->insert(lastSources->end(), s.kSlUs.begin(), s.kSlUs.end());
    }
  }
}

void expectBitwiseEqual(const ParticleData& a, const ParticleData& b) {
  ASSERT_EQ(a.count, b.count);
  EXPECT_EQ(a.globalId, b.globalId); // same internal order too
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.velocity, b.velocity);
  EXPECT_EQ(a.angularVelocity, b.angularVelocity);
  EXPECT_EQ(a.force, b.force);
}
} // namespace

TEST(Determinism, TwoRunsAreBitwiseIdentical) {
  DemSystem a(mixedDeck(), BackendKind::Cpu, 2), b(mixedDeck(), BackendKind::Cpu, 2);
  setGas(a);
  setGas(b);
  std::vector<double> sa, sb;
  run(a, 16, &sa);
  run(b, 16, &sb);
  expectBitwiseEqual(a.particles(), b.particles());
  EXPECT_EQ(sa, sb);
  EXPECT_GT(a.stageTimes().rebuilds, 1u);
}

TEST(Determinism, OneAndTwoThreadsAreBitwiseIdentical) {
  DemSystem a(mixedDeck(), BackendKind::Cpu, 1), b(mixedDeck(), BackendKind::Cpu, 2);
  setGas(a);
  setGas(b);
  std::vector<double> sa, sb;
  run(a, 16, &sa);
  run(b, 16, &sb);
  expectBitwiseEqual(a.particles(), b.particles());
  EXPECT_EQ(sa, sb);
}

TEST(Restart, WriteReadContinueIsBitwiseIdentical) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("coredem_dem_restart_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string file = (dir / "state.h5").string();

  DemSystem straight(mixedDeck(), BackendKind::Cpu, 2);
  setGas(straight);
  run(straight, 8);
  straight.writeState(file);
  std::vector<double> s1, s2;
  run(straight, 8, &s1);

  DemSystem restarted(mixedDeck(), BackendKind::Cpu, 2);
  restarted.readState(file);
  EXPECT_EQ(restarted.step(), 8u * 25u);
  setGas(restarted);
  run(restarted, 8, &s2);
  expectBitwiseEqual(straight.particles(), restarted.particles());
  EXPECT_EQ(s1, s2);
  EXPECT_EQ(straight.time(), restarted.time());
  EXPECT_EQ(straight.step(), restarted.step());

  // A system configured without particle sets takes everything from the file (server restart).
  DemConfig noParticles = mixedDeck();
  noParticles.particleSets.clear();
  DemSystem fromFile(noParticles, BackendKind::Cpu, 1);
  EXPECT_EQ(fromFile.particleCount(), 0u);
  fromFile.readState(file);
  EXPECT_EQ(fromFile.dtDemMax(), straight.dtDemMax());
  setGas(fromFile);
  std::vector<double> s3;
  run(fromFile, 8, &s3);
  expectBitwiseEqual(straight.particles(), fromFile.particles());
  EXPECT_EQ(s1, s3);

  // A state written with another configuration is refused with a clear error.
  DemConfig other = mixedDeck();
  other.materials[0].mu = 0.5;
  DemSystem wrong(other, BackendKind::Cpu, 1);
  EXPECT_THROW(wrong.readState(file), coredem::UserError);
  EXPECT_THROW(wrong.readState((dir / "missing.h5").string()), coredem::UserError);
  std::filesystem::remove_all(dir);
}

// A new start from another run's state (DemSystem::startFromState; case.yaml initial_state):
// time, step and ledgers start at 0 and the pairs' tangential history is kept, so that without
// wall contacts continuing from it is bitwise the restart's continuation (only the clock
// differs, which no force here depends on); materials are matched by name, and a particle whose
// material the new configuration lacks is refused naming it.
TEST(NewStart, KeepsParticlesAndPairHistoryAndMatchesMaterialsByName) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("coredem_dem_new_start_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string file = (dir / "state.h5").string();
  DemConfig c = agitatedDeck(729, false, 11); // no walls: only pair contacts
  c.grid.counts = {3, 3, 3};
  for (int d = 0; d < 3; ++d)
    c.grid.spacing[d] = c.particleSets[0].regionMax[d] / 3;
  DemSystem first(c, BackendKind::Cpu, 1);
  setGas(first);
  run(first, 8);
  first.writeState(file);
  const ParticleData atWrite = first.particles();

  DemConfig noSets = c;
  noSets.particleSets.clear();
  DemSystem restarted(noSets, BackendKind::Cpu, 1);
  restarted.readState(file);
  DemSystem started(noSets, BackendKind::Cpu, 1);
  started.startFromState(file);
  EXPECT_EQ(started.time(), 0.0);
  EXPECT_EQ(started.step(), 0u);
  expectBitwiseEqual(atWrite, started.particles());
  for (DemSystem* s : {&restarted, &started}) {
    setGas(*s);
    run(*s, 8);
  }
  expectBitwiseEqual(restarted.particles(), started.particles());
  EXPECT_GT(restarted.time(), started.time());

  // Materials by name: "default" is material 1 behind a new "steel".
  DemConfig renamed = noSets;
  Material steel = renamed.materials[0];
  steel.name = "steel";
  steel.kn *= 3.0;
  renamed.materials.insert(renamed.materials.begin(), steel);
  renamed.materials[1].mu = 0.5; // another configuration: the hash differs
  DemSystem moved(renamed, BackendKind::Cpu, 1);
  EXPECT_THROW(moved.readState(file), coredem::UserError);
  moved.startFromState(file);
  for (const std::int32_t m : moved.particles().material)
    EXPECT_EQ(m, 1);

  DemConfig missing = noSets;
  missing.materials[0].name = "sand";
  DemSystem refused(missing, BackendKind::Cpu, 1);
  try {
    refused.startFromState(file);
    ADD_FAILURE() << "a state whose material is missing was accepted";
  } catch (const coredem::UserError& e) {
    EXPECT_NE(std::string(e.what()).find("material 'default' have no material of that name"),
              std::string::npos)
        << e.what();
  }
  std::filesystem::remove_all(dir);
}
