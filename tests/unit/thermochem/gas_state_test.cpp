// One gas state per coupling cell (docs/thermochemistry.md "Gas state"): M_mix = 1/Σ Y_k/M_k,
// x_k = Y_k M_mix/M_k, c_k = ρ_cell Y_k/M_k with the per-cell ρ_g the CFD sends. With the ideal-
// gas density ρ = p M_mix/(R T) the concentrations are x_k p/(R T), so the rates that use c_k
// (R4/R5, WGS, data-defined reactions) and those that use x_k p (R1/R2) see the same gas.
#include <cmath>

#include <gtest/gtest.h>

#include <coredem/dem/kernels/clg_oc_reduction.h>
#include <coredem/dem/kernels/nasa7.h>
#include <coredem/dem/kernels/species_particle.h>
#include <coredem/dem/kernels/wgs.h>

namespace k = coredem::dem::kernels;
using k::GasSpecies;
using k::idx;

namespace {
constexpr double kR = 8.314462618; // J/(mol K), as idealGasDensity
constexpr int kN = 5;              // CO, CO2, H2, H2O, N2 (GasSpecies order)

struct Mixture {
  double y[kN];
  double m[kN];
};

Mixture clgGas() {
  // A gasifier-like mixture (mass fractions sum to 1), molar masses of the species table.
  Mixture g{{0.22, 0.31, 0.012, 0.158, 0.3}, {}};
  for (int s = 0; s < kN; ++s)
    g.m[s] = k::molarMass(static_cast<GasSpecies>(s));
  return g;
}

double rel(double a, double b) {
  return std::fabs(a - b) / std::fabs(b);
}
} // namespace

TEST(GasState, IdealGasDensityGivesConcentrationsXpOverRT) {
  const Mixture g = clgGas();
  for (double t : {300.0, 1173.15, 1500.0}) {
    for (double p : {101325.0, 5e5}) {
      double x0[kN], c0[kN];
      const double mMix = k::cellGasState(1.0, g.y, g.m, kN, x0, c0); // M_mix only
      const double rho = k::idealGasDensity(p, mMix, t);
      double x[kN], c[kN];
      EXPECT_EQ(k::cellGasState(rho, g.y, g.m, kN, x, c), mMix);
      double sumX = 0.0;
      for (int s = 0; s < kN; ++s) {
        EXPECT_LT(rel(c[s], x[s] * p / (kR * t)), 1e-12) << "species " << s << " T " << t;
        EXPECT_LT(rel(x[s], g.y[s] * mMix / g.m[s]), 1e-15);
        sumX += x[s];
      }
      EXPECT_NEAR(sumX, 1.0, 1e-14);
      // M_mix = Σ x_k M_k.
      double mx = 0.0;
      for (int s = 0; s < kN; ++s)
        mx += x[s] * g.m[s];
      EXPECT_LT(rel(mx, mMix), 1e-14);
    }
  }
}

TEST(GasState, NoGasSpeciesGivesZeroMoleFractions) {
  const double y[2] = {0.0, 0.0}, m[2] = {0.028, 0.032};
  double x[2] = {1.0, 1.0}, c[2] = {1.0, 1.0};
  EXPECT_EQ(k::cellGasState(1.2, y, m, 2, x, c), 0.0);
  EXPECT_EQ(x[0], 0.0);
  EXPECT_EQ(x[1], 0.0);
  EXPECT_EQ(c[0], 0.0);
}

// The rates that use concentrations give the same result from c_k = ρ Y_k/M_k (ideal-gas ρ) as
// from c_k = x_k p/(R T): WGS (R3, per cell) and oxygen-carrier reduction (R4/R5, per particle).
TEST(GasState, ConcentrationRatesSeeTheSameStateAsXp) {
  const Mixture g = clgGas();
  const double t = 1173.15, p = 101325.0;
  double x0[kN], c0[kN];
  const double mMix = k::cellGasState(1.0, g.y, g.m, kN, x0, c0);
  double x[kN], c[kN], cx[kN];
  k::cellGasState(k::idealGasDensity(p, mMix, t), g.y, g.m, kN, x, c);
  for (int s = 0; s < kN; ++s)
    cx[s] = x[s] * p / (kR * t);
  k::WgsParams wp;
  const auto a = k::wgsCellSourcesFromConcentrations(wp, t, 0.6, c, 1e-3);
  const auto b = k::wgsCellSourcesFromConcentrations(wp, t, 0.6, cx, 1e-3);
  ASSERT_NE(a.omega, 0.0);
  EXPECT_LT(rel(a.omega, b.omega), 1e-12);
  EXPECT_LT(rel(a.heatSource, b.heatSource), 1e-12);
  // The ρ, Y form with the table molar masses is the concentration form with c = ρ Y/M.
  const auto d = k::wgsCellSources(wp, t, 0.6, k::idealGasDensity(p, mMix, t), g.y, 1e-3);
  EXPECT_EQ(d.omega, a.omega);
  // R4/R5 of one carrier particle.
  k::OcReductionParams op;
  const double mf[3] = {0.6, 0.0, 0.4};
  const auto ra = k::ocReduction(op, t, 1e-6, mf, c[idx(GasSpecies::CO)], c[idx(GasSpecies::H2)]);
  const auto rb = k::ocReduction(op, t, 1e-6, mf, cx[idx(GasSpecies::CO)], cx[idx(GasSpecies::H2)]);
  ASSERT_NE(ra.mdotGas[idx(GasSpecies::CO)], 0.0);
  for (int s = 0; s < kN; ++s) {
    if (rb.mdotGas[s] != 0.0) {
      EXPECT_LT(rel(ra.mdotGas[s], rb.mdotGas[s]), 1e-12) << s;
    }
  }
}
