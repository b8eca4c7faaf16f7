// Radiation kernel (docs/physics.md §3.4) and the RK4 reference of the MFiX radiation case (§8.4).
#include <cmath>
#include <iterator>
#include <vector>

#include <gtest/gtest.h>

#include <coredem/dem/kernels/radiation.h>
#include <coredem/dem/verification/analytic.h>

#include "reference/thermochem_reference.h"

namespace k = coredem::dem::kernels;
namespace v = coredem::dem::verification;
namespace ref = coredem::test::thermochem_ref;

// Eq. 27 in factored form equals e σ A (T_env⁴ − T_p⁴) (1e-14 relative), vanishes at
// equilibrium and has the right sign.
TEST(Radiation, HeatMatchesEquation27) {
  const double d = 2e-3;
  const double a = 3.141592653589793 * d * d;
  for (double tp : {300.0, 800.0, 1400.0}) {
    for (double te : {310.0, 1000.0, 1200.0}) {
      const double direct = 0.85 * k::kStefanBoltzmann * a * (std::pow(te, 4) - std::pow(tp, 4));
      EXPECT_NEAR(k::radiationHeat(0.85, d, te, tp), direct, 1e-14 * std::fabs(direct) + 1e-300);
    }
  }
  EXPECT_EQ(k::radiationHeat(0.9, d, 1173.15, 1173.15), 0.0);
  EXPECT_GT(k::radiationHeat(0.9, d, 1200.0, 1100.0), 0.0);
}

// Eq. 28: variant (a) uses the cell mean including i; variant (b) neighbours only, and T_g
// when there are none.
TEST(Radiation, EnvironmentTemperature) {
  const double eps = 0.6;
  const double tg = 1000.0;
  // (a) particles at 900 (self) and 1100 → mean 1000 → T_env = 1000.
  EXPECT_DOUBLE_EQ(k::radiationEnvironmentTemperature(eps, tg, 900.0 + 1100.0, 2), 1000.0);
  // (b) for the particle at 900: neighbour mean 1100 → 0.6·1000 + 0.4·1100 = 1040.
  EXPECT_NEAR(k::radiationEnvironmentTemperature(eps, tg, 1100.0, 1), 1040.0, 1e-12);
  EXPECT_EQ(k::radiationEnvironmentTemperature(eps, tg, 0.0, 0), tg);
}

// Constants of §8.4 vs reference/make_thermochem_reference.py: C_A, C_B, ε_g (1e-12 relative:
// only the order of multiplications and the double rounding of the inputs differ).
TEST(Radiation, MfixCaseConstants) {
  const v::RadiationCase c = v::mfixRadiationCase();
  EXPECT_NEAR(c.epsG, ref::kRadiationVoidage, 1e-13);
  EXPECT_NEAR(v::radiationConstant(c.m1, c.d1), ref::kRadiationCA, 1e-12 * ref::kRadiationCA);
  EXPECT_NEAR(v::radiationConstant(c.m2, c.d2), ref::kRadiationCB, 1e-12 * ref::kRadiationCB);
  // MFiX's constants (2.70024635866355e-10, 1.55333291786026e-10) differ by 2.2e-5 relative
  // because MFiX uses a slightly different σ.
  EXPECT_NEAR(v::radiationConstant(c.m1, c.d1) / 2.70024635866355e-10, 1.0, 3e-5);
}

// RK4, Δt = 1e-3 s, vs the same scheme in Python floats (reference/make_thermochem_reference.py)
// for both T_env variants: the two differ only in the rounding of each step (~1e-13 K), which
// accumulates over up to 3e5 steps → 1e-9 K. And the step is converged (Δt = 1e-3 vs 2e-3
// differ by < 1e-8 K).
TEST(Radiation, Rk4ReferenceMatchesScript) {
  std::vector<double> times;
  for (const auto& r : ref::kRadiationCellMean) {
    times.push_back(r.t);
  }
  const auto ra = v::radiationReferenceRK4(v::mfixRadiationCase(), times, 1e-3);
  const auto rb = v::radiationReferenceRK4(
      v::mfixRadiationCase(k::RadiationEnvironment::NeighbourMeanExcludingSelf), times, 1e-3);
  for (std::size_t i = 0; i < times.size(); ++i) {
    SCOPED_TRACE(times[i]);
    EXPECT_NEAR(ra[i].t1, ref::kRadiationCellMean[i].t1, 1e-9);
    EXPECT_NEAR(ra[i].t2, ref::kRadiationCellMean[i].t2, 1e-9);
    ASSERT_EQ(ref::kRadiationNeighbours[i].t, times[i]);
    EXPECT_NEAR(rb[i].t1, ref::kRadiationNeighbours[i].t1, 1e-9);
    EXPECT_NEAR(rb[i].t2, ref::kRadiationNeighbours[i].t2, 1e-9);
  }
  const auto coarse = v::radiationReferenceRK4(v::mfixRadiationCase(), times, 2e-3);
  for (std::size_t i = 0; i < times.size(); ++i) {
    EXPECT_NEAR(coarse[i].t1, ra[i].t1, 1e-8);
    EXPECT_NEAR(coarse[i].t2, ra[i].t2, 1e-8);
  }
}

// MFiX POST files (§8.4): T_A(49.901 s) = 394.93054359, T_B = 405.99722484 K with MFiX's σ.
// Our σ (CODATA) changes C by 2.2e-5 relative; the resulting difference is < 0.01 K.
TEST(Radiation, CloseToMfixFileValues) {
  const std::vector<double> times = {49.901, 99.9};
  const auto r = v::radiationReferenceRK4(v::mfixRadiationCase(), times, 1e-3);
  EXPECT_NEAR(r[0].t1, 394.93054359, 1e-2);
  EXPECT_NEAR(r[0].t2, 405.99722484, 1e-2);
  EXPECT_NEAR(r[1].t1, 399.87201627, 1e-2);
  EXPECT_NEAR(r[1].t2, 400.83872184, 1e-2);
}

TEST(Radiation, Rk4RejectsBadInput) {
  const std::vector<double> back = {5.0, 1.0};
  EXPECT_THROW(v::radiationReferenceRK4(v::mfixRadiationCase(), back, 1e-3), coredem::UserError);
  const std::vector<double> one = {1.0};
  EXPECT_THROW(v::radiationReferenceRK4(v::mfixRadiationCase(), one, 0.0), coredem::UserError);
}
