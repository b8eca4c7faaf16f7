// Li–Mason / Ranz–Marshall convection (docs/physics.md §3.1) vs the MFiX convection case (§8.3)
// and the Li–Mason table of §8.3.
#include <cmath>
#include <iterator>

#include <gtest/gtest.h>

#include <coredem/dem/kernels/convection.h>
#include <coredem/dem/verification/analytic.h>

#include "reference/thermochem_reference.h"

namespace k = coredem::dem::kernels;
namespace v = coredem::dem::verification;

namespace ref = coredem::test::thermochem_ref;

namespace {
constexpr double kD = 3.6e-3; // particle B
constexpr double kPi = 3.141592653589793;
double cellVoidage() {
  return 1.0 - v::sphereVolume(kD) / (0.04 * 0.04 * 0.0036);
}
} // namespace

// MFiX-CONV, Ranz–Marshall, Re without ε: Re, Pr, Nu and the coefficient h A/(m c) vs
// reference/make_thermochem_reference.py (same inputs, 50 digits) at 1e-12 relative (only the
// unit-conversion and operation rounding differs); and the MFiX file's printed Re = 1376.372,
// Pr = 0.35834, Nu = 17.8107 and coefficient 0.878629815377096 s⁻¹ (15 digits) at their digits.
TEST(Convection, MfixRanzMarshallCoefficient) {
  const k::GasState g = v::musserConvectionGas(298.15, 1.0);
  k::ConvectionParams p;
  p.model = k::NusseltModel::RanzMarshall;
  p.reynoldsWithVoidage = false;
  const double re = k::particleReynolds(g.rho, g.mu, kD, 6.0, 1.0, false);
  EXPECT_NEAR(re, ref::kConvectionReynolds, 1e-12 * re);
  EXPECT_NEAR(k::prandtl(g.mu, g.cp, g.k), ref::kConvectionPrandtl, 1e-12);
  EXPECT_NEAR(k::nusselt(p, g, kD, 6.0), ref::kConvectionNusselt, 1e-12 * ref::kConvectionNusselt);
  EXPECT_NEAR(re, 1376.372, 5e-4);
  EXPECT_NEAR(k::prandtl(g.mu, g.cp, g.k), 0.35834, 5e-6);
  EXPECT_NEAR(k::nusselt(p, g, kD, 6.0), 17.8107, 5e-5);
  const double c = v::convectionCoefficient(p, g, kD, v::musserMaterialB(), 6.0);
  EXPECT_NEAR(c, ref::kConvectionCoefficient, 1e-12 * c);
  EXPECT_NEAR(c, 0.878629815377096, 1e-12 * c);
  EXPECT_NEAR(v::convectionTemperature(298.15, 373.15, c, 1.0), ref::kConvectionTAt1s, 1e-10);
  EXPECT_NEAR(v::convectionTemperature(298.15, 373.15, c, 5.0), ref::kConvectionTAt5s, 1e-10);
  // MFiX reference: T(1 s) = 329.3014 K, T(5 s) = 299.0771 K (printed to 1e-4 K).
  EXPECT_NEAR(v::convectionTemperature(298.15, 373.15, c, 1.0), 329.3014, 5e-5);
  EXPECT_NEAR(v::convectionTemperature(298.15, 373.15, c, 5.0), 299.0771, 5e-5);
}

// docs/physics.md §8.3 Li–Mason table (Nu to 1e-4, coefficient to 1e-6, T(1 s) to 1e-4 K).
TEST(Convection, LiMasonTableOfPhysics) {
  struct Row {
    double u;
    bool withEps;
    double nu;
    double coef;
    double t1;
  };
  const Row rows[] = {{6.0, false, 19.7830, 0.975923, 326.4133},
                      {6.0, true, 19.4774, 0.960850, 326.8426},
                      {0.6, false, 6.9998, 0.345310, 351.2501},
                      {0.6, true, 6.9155, 0.341152, 351.4713}};
  for (const Row& r : rows) {
    SCOPED_TRACE(r.u);
    SCOPED_TRACE(r.withEps);
    // "ε used in Re and in ε^3.5": ε = 1 rows use ε = 1 in both.
    const double eps = r.withEps ? cellVoidage() : 1.0;
    const k::GasState g = v::musserConvectionGas(298.15, eps);
    k::ConvectionParams p; // defaults: Li–Mason, n = 3.5, Re with ε
    EXPECT_NEAR(k::nusselt(p, g, kD, r.u), r.nu, 5e-5);
    const double c = v::convectionCoefficient(p, g, kD, v::musserMaterialB(), r.u);
    EXPECT_NEAR(c, r.coef, 5e-7);
    EXPECT_NEAR(v::convectionTemperature(298.15, 373.15, c, 1.0), r.t1, 5e-5);
  }
  EXPECT_NEAR(cellVoidage(), 0.995759, 5e-7);
}

// Re → 0: Nu → 2 for both correlations and the conductance is the pure-conduction value
// 2π κ_g d_p (exact up to rounding, 1e-15 relative).
TEST(Convection, StagnantGasLimit) {
  const k::GasState g = v::musserConvectionGas(500.0, 0.6);
  for (auto model : {k::NusseltModel::LiMason, k::NusseltModel::RanzMarshall}) {
    k::ConvectionParams p;
    p.model = model;
    EXPECT_DOUBLE_EQ(k::nusselt(p, g, kD, 0.0), 2.0);
    const k::ConvectionResult r = k::convection(p, g, kD, 0.0, 400.0);
    EXPECT_NEAR(r.conductance, 2.0 * kPi * g.k * kD, 1e-15 * r.conductance);
    EXPECT_NEAR(r.heat, r.conductance * 100.0, 1e-15 * r.heat);
    EXPECT_GT(r.heat, 0.0); // hotter gas heats the particle
  }
  // Small Re: Nu − 2 ∝ √Re (ratio for Re ×4 is 2 within rounding).
  k::ConvectionParams p;
  const double n1 = k::nusselt(p, g, kD, 1e-6) - 2.0;
  const double n4 = k::nusselt(p, g, kD, 4e-6) - 2.0;
  EXPECT_NEAR(n4 / n1, 2.0, 1e-9);
}

// Branches of Eq. 21 evaluated by hand, and Li–Mason ≡ Ranz–Marshall at ε = 1, Re < 200.
TEST(Convection, LiMasonBranches) {
  const double pr = 0.7;
  const double eps = 0.8;
  const double en = std::pow(eps, 3.5);
  EXPECT_DOUBLE_EQ(k::nusseltLiMason(199.0, pr, eps, 3.5),
                   2.0 + 0.6 * en * std::sqrt(199.0) * std::cbrt(pr));
  EXPECT_NEAR(k::nusseltLiMason(200.0, pr, eps, 3.5),
              2.0 +
                  (0.5 * en * std::sqrt(200.0) + 0.02 * en * std::pow(200.0, 0.8)) * std::cbrt(pr),
              1e-13);
  EXPECT_NEAR(k::nusseltLiMason(1499.0, pr, eps, 3.5),
              2.0 + (0.5 * en * std::sqrt(1499.0) + 0.02 * en * std::pow(1499.0, 0.8)) *
                        std::cbrt(pr),
              1e-13);
  EXPECT_NEAR(k::nusseltLiMason(1500.0, pr, eps, 3.5), 2.0 + 4.5e-5 * en * std::pow(1500.0, 1.8),
              1e-13);
  EXPECT_DOUBLE_EQ(k::nusseltLiMason(150.0, pr, 1.0, 3.5), k::nusseltRanzMarshall(150.0, pr));
}

// Switches: Re with/without ε, and the ε_min clip of §1.1.
TEST(Convection, VoidageSwitchAndClip) {
  const k::GasState g = v::musserConvectionGas(300.0, 0.5);
  k::ConvectionParams with;
  k::ConvectionParams without;
  without.reynoldsWithVoidage = false;
  const double re = g.rho * kD * 0.3 / g.mu;
  const double pr = k::prandtl(g.mu, g.cp, g.k);
  EXPECT_NEAR(k::nusselt(with, g, kD, 0.3), k::nusseltLiMason(0.5 * re, pr, 0.5, 3.5), 1e-14);
  EXPECT_NEAR(k::nusselt(without, g, kD, 0.3), k::nusseltLiMason(re, pr, 0.5, 3.5), 1e-14);
  k::GasState packed = g;
  packed.eps = 0.1; // over-packed PCM cell → evaluated at ε_min = 0.35
  EXPECT_NEAR(k::nusselt(with, packed, kD, 0.3), k::nusseltLiMason(0.35 * re, pr, 0.35, 3.5),
              1e-14);
}

// Implicit/explicit split: H T_g − (H T_p) equals the cell sum of Q_gp / V_c.
TEST(Convection, CellSourceSplitReproducesParticleSum) {
  k::ConvectionParams p;
  const k::GasState g = v::musserConvectionGas(350.0, 0.9);
  const double vCell = 1e-6;
  k::ConvectionCellSource cell;
  double sumQ = 0.0;
  for (int i = 0; i < 20; ++i) {
    const double d = 1e-3 * (1.0 + 0.05 * i);
    const double tp = 300.0 + 7.0 * i;
    const k::ConvectionResult r = k::convection(p, g, d, 0.1 * i, tp);
    k::addConvectionToCell(cell, r.conductance, tp, 1.0 / vCell);
    sumQ += r.heat;
  }
  // Tolerance: the split form subtracts two sums of ~20 terms of size ~G·T/V; 1e-12 of those.
  EXPECT_NEAR(k::cellConvectionHeat(cell, g.T), sumQ / vCell, 1e-12 * cell.H * g.T);
}

// The heat module evaluates convection from per-cell Nusselt factors computed once per CFD step
// (convectionFromFactors): bitwise the per-particle kernel for both models, with and without ε
// in Re, below the ε clip, and in all three Li–Mason Reynolds ranges (Re ≈ 0 to ≈ 5000).
TEST(Convection, CellFactorsGiveBitwiseTheParticleKernel) {
  int checked = 0;
  for (const k::NusseltModel model : {k::NusseltModel::LiMason, k::NusseltModel::RanzMarshall}) {
    for (const bool withEps : {true, false}) {
      for (const double eps : {0.2, 0.35, 0.41, 0.7, 1.0}) {
        for (const double slip : {0.0, 1e-4, 0.05, 0.9, 4.0, 13.0, 60.0}) {
          k::ConvectionParams p;
          p.model = model;
          p.reynoldsWithVoidage = withEps;
          p.voidageExponent = 4.75;
          k::GasState g = v::musserConvectionGas(340.0, eps);
          const k::ConvectionResult a = k::convection(p, g, 1.3e-3, slip, 415.0);
          const k::ConvectionResult b =
              k::convectionFromFactors(p, k::nusseltFactors(p, g), g, 1.3e-3, slip, 415.0);
          EXPECT_EQ(a.conductance, b.conductance) << "eps " << eps << " slip " << slip;
          EXPECT_EQ(a.heat, b.heat);
          ++checked;
        }
      }
    }
  }
  EXPECT_EQ(checked, 140);
}
