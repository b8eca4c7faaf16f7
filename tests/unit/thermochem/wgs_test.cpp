// Homogeneous water–gas shift (docs/physics.md §6.2): equilibrium consistency, sources, limiter.
#include <cmath>
#include <iterator>

#include <gtest/gtest.h>

#include <coredem/dem/kernels/reaction_enthalpy.h>
#include <coredem/dem/kernels/wgs.h>

#include "reference/thermochem_reference.h"

namespace k = coredem::dem::kernels;
using k::GasSpecies;
using k::idx;

// K_eq options: Yoon–Denn 0.0265 e^(3968/T) is 1.40 at 1000 K vs thermodynamic 1.435 (§6.2,
// within 3 %); the seed's exp(−4.33 + 4577.8/T) and the thermodynamic exp(−ΔG/(R T)) vs
// reference/make_thermochem_reference.py.
TEST(Wgs, EquilibriumConstants) {
  k::WgsParams p;
  EXPECT_NEAR(k::wgsEquilibriumConstant(p, 1000.0), 0.0265 * std::exp(3.968), 1e-15);
  EXPECT_NEAR(k::wgsEquilibriumConstant(p, 1000.0), 1.40, 0.005);
  p.equilibrium = k::WgsEquilibrium::Seed;
  EXPECT_NEAR(k::wgsEquilibriumConstant(p, 1000.0), coredem::test::thermochem_ref::kWgsSeed1000,
              1e-14);
  p.equilibrium = k::WgsEquilibrium::Thermodynamic;
  EXPECT_NEAR(k::wgsEquilibriumConstant(p, 1000.0), coredem::test::thermochem_ref::kWgsThermo1000,
              1e-11);
  k::WgsParams yd;
  for (double t : {1000.0, 1100.0, 1173.15, 1223.15}) { // CLG range (5 % off at 900 K)
    EXPECT_NEAR(k::wgsEquilibriumConstant(yd, t) / k::wgsEquilibriumConstant(p, t), 1.0, 0.03) << t;
  }
}

// At the equilibrium composition of each option the net rate vanishes (to round-off of the
// forward term), below it the reaction runs forward, above it backward.
TEST(Wgs, RateVanishesAtEquilibrium) {
  for (auto opt :
       {k::WgsEquilibrium::YoonDenn, k::WgsEquilibrium::Seed, k::WgsEquilibrium::Thermodynamic}) {
    k::WgsParams p;
    p.equilibrium = opt;
    const double t = 1173.15;
    const double keq = k::wgsEquilibriumConstant(p, t);
    const double cCO = 2.0, cH2O = 3.0, cCO2 = 1.5;
    const double cH2 = keq * cCO * cH2O / cCO2;
    const double forward = 0.7 * p.kf0 * std::exp(-p.efOverR / t) * cCO * cH2O;
    EXPECT_NEAR(k::wgsRate(p, t, 0.7, cCO, cH2O, cCO2, cH2), 0.0, 4e-16 * forward);
    EXPECT_GT(k::wgsRate(p, t, 0.7, cCO, cH2O, cCO2, 0.5 * cH2), 0.0);
    EXPECT_LT(k::wgsRate(p, t, 0.7, cCO, cH2O, cCO2, 2.0 * cH2), 0.0);
  }
}

// A closed batch cell relaxes to the equilibrium of the chosen K_eq (reaction quotient → K to
// 1e-10), conserving mass and each element to round-off.
TEST(Wgs, BatchRelaxesToEquilibriumAndConservesMass) {
  k::WgsParams p;
  p.equilibrium = k::WgsEquilibrium::Thermodynamic;
  const double t = 1173.15;
  const double rho = 0.25;
  double y[k::kGasSpeciesCount] = {0.3, 0.05, 0.01, 0.34, 0.30};
  const double totalMass = rho; // per m³, ε_g = 1
  auto element = [&](double wC, double wH, double wO) {
    double s = 0.0;
    const double comp[5][3] = {{1, 0, 1}, {1, 0, 2}, {0, 2, 0}, {0, 2, 1}, {0, 0, 0}};
    for (int i = 0; i < 5; ++i) {
      s += rho * y[i] / k::molarMass(static_cast<GasSpecies>(i)) *
           (wC * comp[i][0] + wH * comp[i][1] + wO * comp[i][2]);
    }
    return s;
  };
  const double c0 = element(1, 0, 0), h0 = element(0, 1, 0), o0 = element(0, 0, 1);
  const double dt = 1.0;
  for (int step = 0; step < 20000; ++step) {
    const k::WgsCellSources s = k::wgsCellSources(p, t, 1.0, rho, y, dt);
    double sum = 0.0;
    for (int i = 0; i < k::kGasSpeciesCount; ++i) {
      y[i] += dt * s.massSource[i] / rho;
      sum += s.massSource[i];
    }
    // Σ R_n = ω Σ ν M: round-off of four terms, ≤ 4 ulp of the largest.
    ASSERT_NEAR(sum, 0.0, 1e-15 * std::fabs(s.massSource[idx(GasSpecies::CO2)]) + 1e-300);
  }
  double c[5];
  for (int i = 0; i < 5; ++i) {
    c[i] = rho * y[i] / k::molarMass(static_cast<GasSpecies>(i));
  }
  const double q = c[idx(GasSpecies::CO2)] * c[idx(GasSpecies::H2)] /
                   (c[idx(GasSpecies::CO)] * c[idx(GasSpecies::H2O)]);
  EXPECT_NEAR(q, k::wgsEquilibriumConstant(p, t), 1e-10);
  double ySum = 0.0;
  for (double v : y) {
    ySum += v;
  }
  EXPECT_NEAR(ySum * rho, totalMass, 1e-13 * totalMass);
  EXPECT_NEAR(element(1, 0, 0), c0, 1e-12 * c0);
  EXPECT_NEAR(element(0, 1, 0), h0, 1e-12 * h0);
  EXPECT_NEAR(element(0, 0, 1), o0, 1e-12 * o0);
}

// Sources: R_n = ν_n M_n ω, heat = −ΔH_R3(T_g) ω (exothermic forward → heats the gas), and
// the non-negativity limiter caps ω dt at the available reactant.
TEST(Wgs, SourcesHeatAndLimiter) {
  const k::WgsParams p;
  const double t = 1100.0;
  const double y[k::kGasSpeciesCount] = {0.2, 0.0, 0.0, 0.2, 0.6};
  const auto s = k::wgsCellSources(p, t, 0.8, 0.3, y);
  EXPECT_GT(s.omega, 0.0);
  EXPECT_NEAR(s.massSource[idx(GasSpecies::CO)], -k::molarMass(k::Species::CO) * s.omega, 1e-18);
  EXPECT_NEAR(s.massSource[idx(GasSpecies::H2)], k::molarMass(k::Species::H2) * s.omega, 1e-18);
  EXPECT_EQ(s.massSource[idx(GasSpecies::N2)], 0.0);
  EXPECT_NEAR(s.heatSource, -k::reactionEnthalpy(k::ClgReaction::R3, t) * s.omega,
              1e-12 * std::fabs(s.heatSource));
  EXPECT_GT(s.heatSource, 0.0);
  const double cCO = 0.3 * 0.2 / k::molarMass(k::Species::CO);
  const double cH2O = 0.3 * 0.2 / k::molarMass(k::Species::H2O);
  const auto big = k::wgsCellSources(p, t, 0.8, 0.3, y, 1e6); // huge step
  EXPECT_NEAR(big.omega * 1e6, 0.8 * std::min(cCO, cH2O), 1e-12);
  k::WgsParams off;
  off.enabled = false;
  EXPECT_EQ(k::wgsCellSources(off, t, 0.8, 0.3, y).omega, 0.0);
}
