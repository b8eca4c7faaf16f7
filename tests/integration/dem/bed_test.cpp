// A settled packed bed: the walls carry exactly its weight.
#include <gtest/gtest.h>

#include "dem_test_util.h"

using namespace coredem::dem;
using namespace coredem::dem::testing;

TEST(PackedBed, SettledBedWallForceEqualsWeight) {
  DemConfig c;
  c.materials[0].kn = 100; // softer than glass: 2.2× longer Δt_DEM, overlaps still < 0.2 % d
  c.materials[0].en = 0.3; // settles quickly
  c.materials[0].mu = 0.3;
  const double d = 1e-3, L = 8 * d;
  ParticleSet s;
  s.packing = Packing::Random;
  s.count = 200;
  s.diameter = d;
  s.regionMin = {0, 0, 0};
  s.regionMax = {L, L, 3 * L};
  s.seed = 99;
  c.particleSets.push_back(s);
  c.addBox({0, 0, 0}, {L, L, 4 * L});
  DemSystem sys(c, BackendKind::Cpu, 1);
  const double dtCfd = 1e-3;
  const int nSub = TimeHandler::subStepsFor(dtCfd, sys.dtDemMax());
  for (int k = 0; k < 400; ++k)
    sys.advance(dtCfd, nSub); // 0.4 s: fall + settle
  const std::size_t n = sys.particles().count;
  const RestingLoad load = restingLoad(sys);
  EXPECT_LT(load.vmax, 1e-3) << "bed not settled";
  EXPECT_NEAR(load.wallForce[2], load.weight, 1e-3 * load.weight);
  EXPECT_NEAR(load.wallForce[0], 0.0, 1e-3 * load.weight);
  EXPECT_NEAR(load.wallForce[1], 0.0, 1e-3 * load.weight);
  EXPECT_GT(sys.pairContactCount(), n); // a real bed: more than one contact per particle
}

TEST(PackedBed, TooFewHistorySlotsIsAUserError) {
  // A simple-cubic packing: a particle owns the contacts with its neighbours of larger global
  // id, 3 at the first corner (and keeps their history); 2 slots cannot hold them.
  DemConfig c;
  ParticleSet s;
  s.packing = Packing::Lattice;
  s.spacing = 0.999e-3;
  s.count = 27;
  s.regionMin = {0, 0, 0};
  s.regionMax = {3 * 0.999e-3, 3 * 0.999e-3, 3 * 0.999e-3};
  c.particleSets.push_back(s);
  c.neighbour.historySlots = 2;
  DemSystem sys(c, BackendKind::Cpu, 1);
  try {
    sys.advance(sys.dtDemMax(), 1);
    FAIL() << "expected a UserError";
  } catch (const coredem::UserError& e) {
    EXPECT_NE(std::string(e.what()).find("historySlots"), std::string::npos) << e.what();
  }
}
