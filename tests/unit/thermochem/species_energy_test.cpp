// Particle species/mass/diameter update (docs/physics.md §4, Eqs. 31–32, removal §1.1) and the
// particle energy equation (Eq. 18, §3.5).
#include <cmath>

#include <gtest/gtest.h>

#include <coredem/dem/kernels/nasa7.h>
#include <coredem/dem/kernels/particle_energy.h>
#include <coredem/dem/kernels/species_particle.h>

#include "reference/thermochem_reference.h"

namespace k = coredem::dem::kernels;

// Eq. 31: species masses change by dt·ṁ_k; total mass = Σ; fractions renormalised (Σ X = 1
// to 1e-15). Clamping only when a rate overshoots.
TEST(ParticleSpecies, UpdateConservesSpeciesMasses) {
  double m = 2e-6;
  double x[3] = {0.5, 0.2, 0.3};
  const double mdot[3] = {-1e-7, 4e-8, 0.0};
  const double dt = 1e-2;
  const double clamped = k::updateParticleSpecies(m, x, mdot, 3, dt);
  EXPECT_EQ(clamped, 0.0);
  EXPECT_NEAR(m, 2e-6 - 6e-10, 1e-21); // 2e-6 + dt·(−6e-8)
  EXPECT_NEAR(m * x[0], 1e-6 - 1e-9, 1e-21);
  EXPECT_NEAR(m * x[1], 4e-7 + 4e-10, 1e-21);
  EXPECT_NEAR(m * x[2], 6e-7, 1e-21);
  EXPECT_NEAR(x[0] + x[1] + x[2], 1.0, 1e-15);
  // Overshoot: the species mass is clamped at 0 and the added mass is reported.
  double m2 = 1e-6;
  double x2[2] = {0.1, 0.9};
  const double big[2] = {-2e-5, 0.0}; // removes 2e-7 kg of species 0, which has 1e-7
  EXPECT_NEAR(k::updateParticleSpecies(m2, x2, big, 2, 1e-2), 1e-7, 1e-21);
  EXPECT_EQ(x2[0], 0.0);
  EXPECT_NEAR(m2, 9e-7, 1e-21);
}

// Eq. 32 and the removal criterion (d < 0.1 d0 by default).
TEST(ParticleSpecies, ShrinkingDiameterAndRemoval) {
  const double rho = 1540.0;
  const double d0 = 0.48e-3;
  const double m0 = rho * 3.141592653589793 / 6.0 * d0 * d0 * d0;
  EXPECT_NEAR(k::shrinkingDiameter(m0, rho), d0, 1e-15 * d0);
  EXPECT_NEAR(k::shrinkingDiameter(m0 / 8.0, rho), 0.5 * d0, 1e-15 * d0);
  const double dRemove = k::shrinkingDiameter(m0 * 0.999e-3, rho); // just below (0.1)³ of the mass
  EXPECT_TRUE(k::particleShouldBeRemoved(dRemove, d0));
  EXPECT_FALSE(k::particleShouldBeRemoved(k::shrinkingDiameter(m0 * 1.001e-3, rho), d0));
  EXPECT_FALSE(k::particleShouldBeRemoved(0.3 * d0, d0, 0.25));
  EXPECT_TRUE(k::particleShouldBeRemoved(0.2 * d0, d0, 0.25));
}

// Mass → mole fractions and ideal-gas density: steam/N2 1:1 molar at 1173 K, 1 atm gives
// ρ ≈ 0.239 kg/m³ (docs/physics.md §7).
TEST(ParticleSpecies, GasCompositionHelpers) {
  const double mH2O = k::molarMass(k::Species::H2O);
  const double mN2 = k::molarMass(k::Species::N2);
  const double y[2] = {mH2O / (mH2O + mN2), mN2 / (mH2O + mN2)};
  const double molar[2] = {mH2O, mN2};
  double x[2];
  const double mMix = k::moleFractionsFromMassFractions(y, molar, 2, x);
  EXPECT_NEAR(x[0], 0.5, 1e-15);
  EXPECT_NEAR(mMix, 0.5 * (mH2O + mN2), 1e-17);
  const double rho = k::idealGasDensity(101325.0, mMix, 1173.0);
  EXPECT_NEAR(rho, 0.239, 0.0005);
  EXPECT_NEAR(k::molarConcentration(rho, y[0], mH2O), 0.5 * 101325.0 / (8.314462618 * 1173.0),
              1e-12);
}

// Eq. 18: dT/dt = ΣQ/(m C_p); Euler update; Q_rxn = −Σ ΔH ṅ.
TEST(ParticleEnergy, RightHandSideAndEuler) {
  k::ParticleHeatSources s;
  s.contactConduction = 1e-3;
  s.lensConduction = -2e-4;
  s.convection = 5e-4;
  s.radiation = -1e-4;
  const double dH[2] = {1.5e5, -4e4};
  const double nDot[2] = {2e-9, 1e-9};
  s.reaction = k::heterogeneousReactionHeat(dH, nDot, 2);
  EXPECT_NEAR(s.reaction, -(1.5e5 * 2e-9) + 4e4 * 1e-9, 1e-18);
  const double q = 1e-3 - 2e-4 + 5e-4 - 1e-4 + s.reaction;
  EXPECT_NEAR(k::particleHeatRate(s), q, 1e-18);
  const double m = 2e-6, cp = 900.0, dt = 1e-4;
  EXPECT_NEAR(k::particleTemperatureRate(s, m, cp), q / (m * cp), 1e-12);
  EXPECT_NEAR(k::particleTemperatureEuler(1000.0, s, m, cp, dt), 1000.0 + dt * q / (m * cp), 1e-12);
}

// Mixture C_p of an OC particle (60 % Fe2O3 / 40 % Al2O3) from NASA-7 at 1173.15 K, vs the
// per-species values of reference/make_thermochem_reference.py (142.4 and 127.1 J/mol/K, §3.5).
TEST(ParticleEnergy, MixtureHeatCapacity) {
  const k::Species sp[2] = {k::Species::Fe2O3, k::Species::Al2O3};
  const double xf[2] = {0.6, 0.4};
  const double cp = k::particleCpFromSpecies(sp, xf, 2, 1173.15);
  auto cpRef = [](k::Species s) {
    for (const auto& r : coredem::test::thermochem_ref::kNasa7) {
      if (r.species == s && r.t == 1173.15) {
        return r.cp;
      }
    }
    return 0.0;
  };
  const double expect = 0.6 * cpRef(k::Species::Fe2O3) / k::molarMass(k::Species::Fe2O3) +
                        0.4 * cpRef(k::Species::Al2O3) / k::molarMass(k::Species::Al2O3);
  ASSERT_GT(expect, 0.0);
  EXPECT_NEAR(cp, expect, 1e-9 * expect);
}
