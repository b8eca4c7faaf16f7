// NASA-7 data, reaction enthalpies and equilibrium constants vs docs/physics.md §3.5 / Appendix A
// and reference numbers computed independently (mpmath, 50 digits) from the same Burcat/MFiX
// coefficients by reference/make_thermochem_reference.py (thermochem_reference.h).
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <coredem/dem/kernels/nasa7.h>
#include <coredem/dem/kernels/reaction_enthalpy.h>

#include "reference/thermochem_reference.h"

namespace k = coredem::dem::kernels;
using k::Species;

namespace ref = coredem::test::thermochem_ref;

// Same polynomials evaluated in a different order (Horner vs term sums): agreement to a few
// ulp of the largest term. Tolerances: C_p and S 1e-12 relative; H 1e-12 relative to the
// largest polynomial term R·|a6| (≤ 2e5 R), i.e. ≤ 2e-6 J/mol, because H can be a small
// difference of large terms (e.g. H2 at 300 K = 53 J/mol).
TEST(Nasa7, MatchesReferenceScript) {
  for (const auto& r : ref::kNasa7) {
    SCOPED_TRACE(static_cast<int>(r.species));
    SCOPED_TRACE(r.t);
    EXPECT_NEAR(k::nasa7CpMolar(r.species, r.t), r.cp, 1e-12 * r.cp);
    EXPECT_NEAR(k::nasa7EntropyMolar(r.species, r.t), r.s, 1e-12 * r.s);
    EXPECT_NEAR(k::nasa7EnthalpyMolar(r.species, r.t), r.h, 2e-6);
  }
}

// docs/physics.md §3.5 table, rounded to the printed digits (H 0.01 kJ/mol, C_p 0.01 J/mol/K; the
// oxide C_p at 0.1 J/mol/K).
TEST(Nasa7, FormationEnthalpiesAndHeatCapacitiesOfPhysicsTable) {
  struct Row {
    Species s;
    double hf;    // kJ/mol
    double cp298; // J/mol/K
    double cp1173;
    double cpTol;
  };
  const Row rows[] = {
      {Species::CO, -110.53, 29.14, 33.96, 0.005},   {Species::CO2, -393.51, 37.14, 55.90, 0.005},
      {Species::H2, 0.0, 28.84, 30.97, 0.005},       {Species::H2O, -241.82, 33.59, 43.61, 0.005},
      {Species::N2, 0.0, 29.12, 33.52, 0.005},       {Species::C, 0.0, 8.53, 22.49, 0.005},
      {Species::Fe2O3, -824.24, 103.9, 142.4, 0.05}, {Species::Fe3O4, -1118.38, 150.7, 197.1, 0.05},
      {Species::Al2O3, -1675.69, 79.0, 127.1, 0.05}};
  for (const Row& r : rows) {
    SCOPED_TRACE(static_cast<int>(r.s));
    EXPECT_NEAR(k::nasa7EnthalpyMolar(r.s, k::kTref) / 1000.0, r.hf, 0.005);
    EXPECT_NEAR(k::nasa7CpMolar(r.s, k::kTref), r.cp298, r.cpTol);
    EXPECT_NEAR(k::nasa7CpMolar(r.s, 1173.15), r.cp1173, r.cpTol);
  }
}

// Interval selection: below the break the low set, at and above it the upper set.
TEST(Nasa7, IntervalSelection) {
  const k::Nasa7Data co = k::nasa7Data(Species::CO);
  EXPECT_EQ(k::nasa7IntervalIndex(co, 999.999), 0);
  EXPECT_EQ(k::nasa7IntervalIndex(co, 1000.0), 1);
  const k::Nasa7Data fe = k::nasa7Data(Species::Fe2O3);
  EXPECT_EQ(k::nasa7IntervalIndex(fe, 500.0), 0);
  EXPECT_EQ(k::nasa7IntervalIndex(fe, 980.0), 1);
  EXPECT_EQ(k::nasa7IntervalIndex(fe, 1200.0), 2);
  EXPECT_EQ(k::nasa7IntervalIndex(fe, 5000.0), 2); // extrapolates the last interval
  EXPECT_TRUE(k::nasa7InRange(Species::Fe3O4, 1173.15));
  EXPECT_FALSE(k::nasa7InRange(Species::Fe3O4, 2000.0));
  EXPECT_FALSE(k::nasa7InRange(Species::Fe2O3, 250.0));
}

// The Burcat fits are continuous at the 1000 K break to well below 1 J/mol (H) and 0.1 %
// (C_p); a wrong coefficient set would break this by orders of magnitude.
TEST(Nasa7, ContinuousAtTheMidpointForGases) {
  for (Species s :
       {Species::CO, Species::CO2, Species::H2, Species::H2O, Species::N2, Species::C}) {
    SCOPED_TRACE(static_cast<int>(s));
    const double below = 1000.0 * (1.0 - 1e-12);
    EXPECT_NEAR(k::nasa7EnthalpyMolar(s, below), k::nasa7EnthalpyMolar(s, 1000.0), 1.0);
    EXPECT_NEAR(k::nasa7CpMolar(s, below), k::nasa7CpMolar(s, 1000.0),
                1e-3 * k::nasa7CpMolar(s, 1000.0));
  }
}

// ΔH_r(T) vs the reference script (mpmath) → 1e-9 relative (the script's ΔH_r is exact to its
// 50 digits; the kernel's sum of ν H in double cancels by up to 10× on R4/R5: ≤ 1e-14 observed).
TEST(ReactionEnthalpy, MatchesReferenceScript) {
  for (const auto& r : ref::kReactionEnthalpy) {
    const double dh[5] = {r.r1, r.r2, r.r3, r.r4, r.r5};
    for (int i = 0; i < 5; ++i) {
      SCOPED_TRACE(r.t);
      SCOPED_TRACE(i);
      EXPECT_NEAR(k::reactionEnthalpy(static_cast<k::ClgReaction>(i), r.t), dh[i],
                  1e-9 * std::fabs(dh[i]));
    }
  }
  // docs/physics.md §3.5 table (kJ/mol, rounded): R1 +172.45 and R4 −47.0 at 298.15 K.
  EXPECT_NEAR(k::reactionEnthalpy(k::ClgReaction::R1, 298.15) / 1e3, 172.45, 0.005);
  EXPECT_NEAR(k::reactionEnthalpy(k::ClgReaction::R4, 298.15) / 1e3, -47.0, 0.05);
}

// Thermodynamic WGS equilibrium constant exp(−ΔG/(R T)) vs the reference script: 1e-11 (ΔG/(R T)
// is a difference of terms ~40 times larger, so double loses ~2 digits).
TEST(ReactionEnthalpy, WgsEquilibriumConstantFromGibbs) {
  const k::Stoichiometry wgs = k::clgStoichiometry(k::ClgReaction::R3);
  EXPECT_NEAR(k::equilibriumConstant(wgs, 1000.0), ref::kWgsThermo1000, 1e-11);
  EXPECT_NEAR(k::equilibriumConstant(wgs, 1173.15), ref::kWgsThermo1173, 1e-11);
}

// Molar masses from atomic masses: every CLG reaction balances to round-off (a few ulp of
// the largest term, 3 M_Fe2O3 ≈ 0.48 kg/mol → 2e-16), and they match docs/physics.md §6 to 2e-6.
TEST(ReactionEnthalpy, ReactionsBalanceMassToRoundOff) {
  for (int i = 0; i < static_cast<int>(k::ClgReaction::Count); ++i) {
    SCOPED_TRACE(i);
    EXPECT_LE(std::fabs(k::stoichiometricMassBalance(
                  k::clgStoichiometry(static_cast<k::ClgReaction>(i)))),
              2e-16);
  }
  struct Row {
    Species s;
    double gPerMol;
  };
  const Row table[] = {
      {Species::C, 12.011},      {Species::CO, 28.010},     {Species::CO2, 44.009},
      {Species::H2, 2.016},      {Species::H2O, 18.015},    {Species::N2, 28.014},
      {Species::Fe2O3, 159.688}, {Species::Fe3O4, 231.533}, {Species::Al2O3, 101.961}};
  for (const Row& r : table) {
    SCOPED_TRACE(static_cast<int>(r.s));
    EXPECT_NEAR(k::molarMass(r.s) * 1e3, r.gPerMol, 2.1e-3);
  }
}

// The combined ΔH_r polynomial (one NASA-7-form polynomial per piece, pieces split at every
// species' interval break) equals the species sum Σ ν H_n(T) over 250–3000 K in 1 K steps and
// just below/at/just above every break (both sides of every T_mid), for R1–R5 and a generic
// reaction mixing species with different breaks (Fe2O3 960/1000 K, Fe3O4 850/1000 K, Al2O3
// 1000/1200 K). The only difference is the summation order, so the error is round-off of a
// cancelling sum: bounded by 1e-12 Σ|ν_n H_n(T)| everywhere, and 1e-12 |ΔH_r| wherever |ΔH_r| ≥
// 1e-3 Σ|ν_n H_n| (everywhere except close to a zero of ΔH_r, e.g. R4 extrapolated far past its
// data near 2600 K or R5 near 900 K, where no relative bound on ΔH_r itself can hold).
TEST(ReactionEnthalpy, CombinedPolynomialEqualsSpeciesSum) {
  std::vector<std::pair<const char*, k::Stoichiometry>> reactions;
  const char* names[] = {"R1", "R2", "R3", "R4", "R5"};
  for (int i = 0; i < 5; ++i)
    reactions.emplace_back(names[i], k::clgStoichiometry(static_cast<k::ClgReaction>(i)));
  // Generic (not a real reaction; the identity holds for any ν): six species, four breaks.
  reactions.emplace_back("generic", k::Stoichiometry{6,
                                                     {Species::Fe3O4, Species::Al2O3, Species::H2,
                                                      Species::Fe2O3, Species::N2, Species::C},
                                                     {-1.0, 0.5, 2.0, 1.5, -0.25, -3.0}});
  for (const auto& [name, st] : reactions) {
    SCOPED_TRACE(name);
    const k::ReactionEnthalpyPoly h = k::combineReactionEnthalpy(st);
    ASSERT_GT(h.n, 0);
    std::vector<double> temps;
    for (double t = 250.0; t <= 3000.0; t += 1.0)
      temps.push_back(t);
    // Every break of every species, from both sides.
    int breaks = 0;
    for (int s = 0; s < st.n; ++s) {
      const k::Nasa7Data d = k::nasa7Data(st.species[s]);
      for (int i = 0; i + 1 < d.n; ++i) {
        const double b = d.iv[i].tMax;
        ++breaks;
        for (double t : {std::nextafter(b, 0.0), b, std::nextafter(b, 1e9), b - 1e-6, b + 1e-6})
          temps.push_back(t);
      }
    }
    EXPECT_GE(h.n, 2);
    EXPECT_LE(h.n, breaks + 1);
    double worst = 0.0;
    std::size_t relChecked = 0;
    for (double t : temps) {
      const double ref = k::reactionEnthalpy(st, t);
      const double got = k::reactionEnthalpy(h, t);
      double scale = 0.0;
      for (int s = 0; s < st.n; ++s)
        scale += std::fabs(st.nu[s] * k::nasa7EnthalpyMolar(st.species[s], t));
      ASSERT_NEAR(got, ref, 1e-12 * scale) << "T = " << t;
      if (std::fabs(ref) >= 1e-3 * scale) {
        ++relChecked;
        worst = std::max(worst, std::fabs(got - ref) / std::fabs(ref));
        ASSERT_NEAR(got, ref, 1e-12 * std::fabs(ref)) << "T = " << t;
      }
    }
    EXPECT_GT(relChecked, temps.size() * 3 / 4); // the relative bound covers most of the range
    RecordProperty(std::string("worst_rel_") + name, std::to_string(worst));
  }
  // The generic reaction's pieces split at 850, 960, 1000 and 1200 K.
  const k::ReactionEnthalpyPoly g = k::combineReactionEnthalpy(reactions.back().second);
  ASSERT_EQ(g.n, 5);
  EXPECT_EQ(g.tUpper[0], 850.0);
  EXPECT_EQ(g.tUpper[1], 960.0);
  EXPECT_EQ(g.tUpper[2], 1000.0);
  EXPECT_EQ(g.tUpper[3], 1200.0);
}
