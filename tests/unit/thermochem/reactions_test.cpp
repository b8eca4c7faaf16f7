// Heterogeneous reactions: the generic data-defined reaction (docs/physics.md §8.5), char
// gasification R1/R2 (§6.1) and oxygen-carrier reduction R4/R5 (§6.3).
#include <cmath>

#include <gtest/gtest.h>

#include <coredem/dem/kernels/clg_char_gasification.h>
#include <coredem/dem/kernels/clg_oc_reduction.h>
#include <coredem/dem/kernels/reaction_enthalpy.h>
#include <coredem/dem/kernels/reaction_generic.h>
#include <coredem/dem/kernels/species_particle.h>
#include <coredem/dem/verification/analytic.h>

namespace k = coredem::dem::kernels;
namespace v = coredem::dem::verification;
using k::GasSpecies;
using k::idx;

namespace {

// A(g) + 2B(s) → C(g) + D(s); particle solids [B, D, I], gas [A, C].
k::HeterogeneousReaction mfixReaction(const v::ReactionCase& c) {
  k::HeterogeneousReaction r;
  r.n = 4;
  const k::ReactionPhase g = k::ReactionPhase::Gas, s = k::ReactionPhase::Solid;
  const k::ReactionPhase ph[4] = {g, s, g, s};
  const int index[4] = {0, 0, 1, 1};
  const double nu[4] = {-1.0, -2.0, 1.0, 1.0};
  const double mm[4] = {c.molarA, c.molarB, c.molarC, c.molarD};
  for (int i = 0; i < 4; ++i) {
    r.phase[i] = ph[i];
    r.index[i] = index[i];
    r.nu[i] = nu[i];
    r.molarMass[i] = mm[i];
  }
  r.law = k::RateLaw::Constant;
  r.A = c.omega;
  return r;
}

} // namespace

// §8.5 numbers: −r_B = 1.1781e-5, r_D = 9.8175e-6, dm/dt = −1.9635e-6 kg/s, gas A consumed at
// 9.8175e-6 and C produced at 1.1781e-5 kg/s (exact products of the inputs → 1e-14 relative).
TEST(GenericReaction, MfixRatesAndBalance) {
  const v::ReactionCase c = v::mfixReactionCase();
  const k::HeterogeneousReaction r = mfixReaction(c);
  EXPECT_EQ(k::heterogeneousMassImbalance(r), 0.0); // 25 + 30 = 30 + 25 g/mol exactly
  const double solid[3] = {c.m0 * c.xB0, 0.0, c.m0 * c.xI0};
  const double w = k::heterogeneousExtentRate(r, 300.0, nullptr, solid, 1e-3);
  EXPECT_EQ(w, c.omega);
  double sRate[3] = {0, 0, 0};
  double gRate[2] = {0, 0};
  k::addHeterogeneousSources(r, w, sRate, gRate);
  EXPECT_NEAR(-sRate[0], 1.1781e-5, 1e-14 * 1.1781e-5);
  EXPECT_NEAR(sRate[1], 9.8175e-6, 1e-14 * 9.8175e-6);
  EXPECT_NEAR(sRate[0] + sRate[1], -1.9635e-6, 1e-13 * 1.9635e-6);
  EXPECT_NEAR(-gRate[0], 9.8175e-6, 1e-14 * 9.8175e-6);
  EXPECT_NEAR(gRate[1], 1.1781e-5, 1e-14 * 1.1781e-5);
  EXPECT_NEAR(sRate[0] + sRate[1] + gRate[0] + gRate[1], 0.0, 1e-20);
  EXPECT_EQ(k::heterogeneousHeat(r, w), 0.0); // ΔH = 0 in this case
}

// Availability: no reaction without B; in a step the consumption is capped at what is left.
TEST(GenericReaction, AvailabilityLimit) {
  const v::ReactionCase c = v::mfixReactionCase();
  const k::HeterogeneousReaction r = mfixReaction(c);
  const double none[3] = {0.0, 1e-5, 1e-5};
  EXPECT_EQ(k::heterogeneousExtentRate(r, 300.0, nullptr, none, 1e-3), 0.0);
  const double little[3] = {1e-9, 1e-5, 1e-5};
  const double w = k::heterogeneousExtentRate(r, 300.0, nullptr, little, 1e-3);
  EXPECT_NEAR(w * 2.0 * c.molarB * 1e-3, 1e-9, 1e-24);
  EXPECT_EQ(k::heterogeneousExtentRate(r, 300.0, nullptr, little, 0.0), c.omega); // no dt limit
}

// Arrhenius law with a gas-concentration order, against the formula by hand.
TEST(GenericReaction, ArrheniusRate) {
  k::HeterogeneousReaction r;
  r.n = 2;
  r.phase[0] = k::ReactionPhase::Gas;
  r.index[0] = 1;
  r.nu[0] = -1.0;
  r.molarMass[0] = 0.028;
  r.phase[1] = k::ReactionPhase::Solid;
  r.index[1] = 0;
  r.nu[1] = 1.0;
  r.molarMass[1] = 0.028;
  r.law = k::RateLaw::Arrhenius;
  r.A = 3.0e2;
  r.beta = 0.5;
  r.E = 80e3;
  r.orderTerm = 0;
  r.order = 0.7;
  const double conc[2] = {0.0, 4.2};
  const double t = 1100.0;
  const double expect =
      3.0e2 * std::sqrt(t) * std::exp(-80e3 / (8.314462618 * t)) * std::pow(4.2, 0.7);
  EXPECT_NEAR(k::heterogeneousRate(r, t, conc), expect, 1e-14 * expect);
  const double zero[2] = {0.0, 0.0};
  EXPECT_EQ(k::heterogeneousRate(r, t, zero), 0.0);
}

// ---- char gasification ----------------------------------------------------------------------

// docs/physics.md §6.1 sanity value: 1223 K, P_H2O = 0.5 bar, P_H2 = 0.05 bar → r_H2O ≈ 2.7e-3 s⁻¹
// (stated to 2 digits; the exact value of the formula is checked to 1e-14).
TEST(CharGasification, LangmuirHinshelwoodRates) {
  const k::CharGasificationParams p;
  const double t = 1223.0;
  const double rW = k::charRateH2O(p, t, 0.5, 0.05);
  const double kW = 1e7 * std::exp(-210e3 / (8.314462618 * t));
  EXPECT_NEAR(rW, kW * 0.5 / (1.0 + 0.5 + 10.0 * 0.05), 1e-14 * rW);
  EXPECT_NEAR(rW, 2.7e-3, 0.05e-3);
  const double rC = k::charRateCO2(p, t, 0.3, 0.1);
  const double kC = 1e7 * std::exp(-230e3 / (8.314462618 * t));
  EXPECT_NEAR(rC, kC * 0.3 / (1.0 + 0.3 + 10.0 * 0.1), 1e-14 * rC);
  EXPECT_LT(rC, rW); // CO2 gasification is slower than steam gasification
}

// Per-particle rates: shrinking-core factor (m_C/m_C0)^(2/3), stoichiometry, mass conservation
// to round-off and heat = −ΣΔH ṅ.
TEST(CharGasification, ParticleRatesConserveMass) {
  const k::CharGasificationParams p;
  double pBar[k::kGasSpeciesCount] = {};
  pBar[idx(GasSpecies::CO2)] = 0.2;
  pBar[idx(GasSpecies::CO)] = 0.05;
  pBar[idx(GasSpecies::H2O)] = 0.5;
  pBar[idx(GasSpecies::H2)] = 0.05;
  const double t = 1173.15;
  const double mC0 = 1540.0 * v::sphereVolume(0.48e-3);
  const auto full = k::charGasification(p, t, pBar, mC0, mC0);
  const auto half = k::charGasification(p, t, pBar, 0.125 * mC0, mC0);
  EXPECT_NEAR(half.nR1 / full.nR1, 0.25, 1e-14); // (1/8)^(2/3)
  EXPECT_NEAR(half.nR2 / full.nR2, 0.25, 1e-14);
  EXPECT_NEAR(full.nR2, mC0 / k::molarMass(k::Species::C) * k::charRateH2O(p, t, 0.5, 0.05),
              1e-14 * full.nR2);
  double gas = 0.0;
  for (double m : full.mdotGas) {
    gas += m;
  }
  EXPECT_NEAR(full.mdotC + gas, 0.0, 1e-15 * std::fabs(full.mdotC));
  EXPECT_NEAR(full.mdotGas[idx(GasSpecies::CO)],
              k::molarMass(k::Species::CO) * (2.0 * full.nR1 + full.nR2),
              1e-15 * full.mdotGas[idx(GasSpecies::CO)]);
  const double q = -k::reactionEnthalpy(k::ClgReaction::R1, t) * full.nR1 -
                   k::reactionEnthalpy(k::ClgReaction::R2, t) * full.nR2;
  EXPECT_NEAR(full.heat, q, 1e-14 * std::fabs(q));
  EXPECT_LT(full.heat, 0.0); // endothermic: the particle is cooled
  const auto gone = k::charGasification(p, t, pBar, 0.0, mC0);
  EXPECT_EQ(gone.nR1 + gone.nR2, 0.0);
  // Step limiter: a step that would burn more carbon than present is scaled to burn all of it.
  const double mLeft = 1e-20;
  const double dt = 1.0;
  const auto r = k::charGasification(p, t, pBar, mLeft, mC0);
  const double s = k::charStepLimiter(r, mLeft, dt);
  EXPECT_NEAR(-r.mdotC * s * dt, std::min(mLeft, -r.mdotC * dt), 1e-15 * mLeft);
  EXPECT_EQ(k::charStepLimiter(full, mC0, 1e-6), 1.0);
}

// ---- oxygen-carrier reduction ---------------------------------------------------------------

// Conversion and rates; full-conversion times τ = ρ_m r_g/(b k_s Cⁿ) of docs/physics.md §6.3 ("≈
// 200 s for CO and ≈ 35 s for H2" at 1223 K, C = 1 mol/m³, stated to ~2 digits → ±10 %).
TEST(OcReduction, RatesAndConversionTimes) {
  const k::OcReductionParams p;
  const double t = 1223.0;
  const double x0[3] = {0.6, 0.0, 0.4};
  const double m = 3734.0 * v::sphereVolume(0.48e-3);
  const auto r = k::ocReduction(p, t, m, x0, 1.0, 1.0);
  EXPECT_EQ(r.conversion, 0.0);
  const double mEq = m * 0.6;
  // dξ/dt at ξ = 0 is k = ṅ · 3 M_Fe2O3 / m_eq, and τ = 3/k for the shrinking core.
  const double tauCO = 3.0 / (r.nR4 * 3.0 * k::molarMass(k::Species::Fe2O3) / mEq);
  const double tauH2 = 3.0 / (r.nR5 * 3.0 * k::molarMass(k::Species::Fe2O3) / mEq);
  EXPECT_NEAR(tauCO, 200.0, 20.0);
  EXPECT_NEAR(tauH2, 35.0, 3.5);
  const double ks = 1e-4 * std::exp(-20e3 / (8.314462618 * t));
  EXPECT_NEAR(tauCO, 32811.0 * 2.6e-7 / (3.0 * ks), 1e-12 * tauCO);
}

// Mass conservation (consistent molar masses → round-off), Fe2O3-equivalent mass conserved
// along a reduction path, ξ → 1 stops the reaction, and the step limiter.
TEST(OcReduction, ConservationAlongAReductionPath) {
  const k::OcReductionParams p;
  const double t = 1173.15;
  double m = 3734.0 * v::sphereVolume(0.48e-3);
  double x[3] = {0.6, 0.0, 0.4};
  const double mAl = m * x[2];
  auto mEqOf = [&] {
    return m * (x[0] + x[1] * 3.0 * k::molarMass(k::Species::Fe2O3) /
                           (2.0 * k::molarMass(k::Species::Fe3O4)));
  };
  const double mEq0 = mEqOf();
  double gasMass = 0.0;
  const double m0 = m;
  const double dt = 0.05;
  for (int step = 0; step < 4000; ++step) {
    auto r = k::ocReduction(p, t, m, x, 2.0, 3.0);
    const double s = k::ocStepLimiter(r, m, x, dt);
    double mdot[3];
    for (int i = 0; i < 3; ++i) {
      mdot[i] = s * r.mdotSolid[i];
    }
    double g = 0.0;
    for (double v : r.mdotGas) {
      g += s * v;
    }
    EXPECT_NEAR(mdot[0] + mdot[1] + g, 0.0, 1e-15 * std::fabs(mdot[0]) + 1e-30);
    gasMass += g * dt;
    k::updateParticleSpecies(m, x, mdot, 3, dt);
  }
  // 4000 steps of round-off-level imbalance: 1e-12 relative.
  EXPECT_NEAR(m + gasMass, m0, 1e-12 * m0);
  EXPECT_NEAR(mEqOf(), mEq0, 1e-12 * mEq0);
  EXPECT_NEAR(m * x[2], mAl, 1e-12 * mAl); // inert
  const auto r = k::ocReduction(p, t, m, x, 2.0, 3.0);
  EXPECT_GT(r.conversion, 0.999);
  // Total mass loss = M_O per mol of reaction: m0 − m = (M_O/(3 M_Fe2O3)) · (Fe2O3 reduced).
  const double reduced = mEq0 * r.conversion;
  EXPECT_NEAR(m0 - m, reduced * 15.999e-3 / (3.0 * k::molarMass(k::Species::Fe2O3)),
              1e-10 * (m0 - m));
}

// ---- the engine's hoisted kernels equal the reference ones ------------------------------------

// charGasificationHoisted / ocReductionHoisted (1/(RT) once, no exp for T-independent adsorption,
// one exp instead of exp·pow, combined ΔH_r polynomials) give the reference kernels' rates and
// heat to 1e-12 relative (round-off of the reordered arithmetic: exp of an argument |x| ≲ 30
// carries ~|x|·1e-16), over 600–1600 K and several compositions, including absent gases. The
// heat is a cancelling sum (ΔH_R5 changes sign near 900 K): its bound is 1e-12 Σ_j ṅ_j Σ_n |ν_n
// H_n|.
namespace {
double enthalpyScale(k::ClgReaction r, double t) {
  const k::Stoichiometry st = k::clgStoichiometry(r);
  double s = 0.0;
  for (int n = 0; n < st.n; ++n)
    s += std::fabs(st.nu[n] * k::nasa7EnthalpyMolar(st.species[n], t));
  return s;
}
} // namespace
TEST(HoistedKernels, CharAndOcEqualTheReferenceKernels) {
  const k::CharGasificationParams cp;
  const k::OcReductionParams op;
  const k::ReactionEnthalpyPoly charDh[2] = {
      k::combineReactionEnthalpy(k::clgStoichiometry(k::ClgReaction::R1)),
      k::combineReactionEnthalpy(k::clgStoichiometry(k::ClgReaction::R2))};
  const k::ReactionEnthalpyPoly ocDh[2] = {
      k::combineReactionEnthalpy(k::clgStoichiometry(k::ClgReaction::R4)),
      k::combineReactionEnthalpy(k::clgStoichiometry(k::ClgReaction::R5))};
  auto near = [](double got, double ref, const char* what, double t) {
    EXPECT_NEAR(got, ref, 1e-12 * std::fabs(ref)) << what << " T = " << t;
  };
  const double pBars[3][5] = {
      {0.05, 0.2, 0.05, 0.5, 0.2}, {0.1, 0.0, 0.1, 0.3, 0.5}, {0.2, 0.3, 0.0, 0.0, 0.5}};
  const double mC0 = 1540.0 * v::sphereVolume(0.48e-3);
  const double m = 3734.0 * v::sphereVolume(0.48e-3);
  const double x[3] = {0.3, 0.2, 0.5};
  const double conc[3][2] = {{2.0, 3.0}, {0.0, 1.5}, {0.7, 0.0}};
  int nonzero = 0;
  for (double t = 600.0; t <= 1600.0; t += 37.0) {
    for (const auto& pb : pBars) {
      const auto ref = k::charGasification(cp, t, pb, 0.3 * mC0, mC0);
      const auto got = k::charGasificationHoisted(cp, charDh, t, pb, 0.3 * mC0, mC0);
      near(got.nR1, ref.nR1, "nR1", t);
      near(got.nR2, ref.nR2, "nR2", t);
      near(got.mdotC, ref.mdotC, "mdotC", t);
      for (int g = 0; g < k::kGasSpeciesCount; ++g)
        near(got.mdotGas[g], ref.mdotGas[g], "mdotGas", t);
      EXPECT_NEAR(got.heat, ref.heat,
                  1e-12 * (enthalpyScale(k::ClgReaction::R1, t) * ref.nR1 +
                           enthalpyScale(k::ClgReaction::R2, t) * ref.nR2))
          << t;
      EXPECT_EQ(k::charGasificationHoisted(cp, nullptr, t, pb, 0.3 * mC0, mC0).heat, 0.0);
      nonzero += ref.nR1 > 0.0 && ref.nR2 > 0.0 ? 1 : 0;
    }
    for (const auto& c : conc) {
      const auto ref = k::ocReduction(op, t, m, x, c[0], c[1]);
      const auto got = k::ocReductionHoisted(op, ocDh, t, m, x, c[0], c[1]);
      near(got.nR4, ref.nR4, "nR4", t);
      near(got.nR5, ref.nR5, "nR5", t);
      EXPECT_EQ(got.conversion, ref.conversion);
      for (int s = 0; s < 3; ++s)
        near(got.mdotSolid[s], ref.mdotSolid[s], "mdotSolid", t);
      for (int g = 0; g < k::kGasSpeciesCount; ++g)
        near(got.mdotGas[g], ref.mdotGas[g], "mdotGas", t);
      EXPECT_NEAR(got.heat, ref.heat,
                  1e-12 * (enthalpyScale(k::ClgReaction::R4, t) * ref.nR4 +
                           enthalpyScale(k::ClgReaction::R5, t) * ref.nR5))
          << t;
    }
  }
  EXPECT_GT(nonzero, 0);
  // No reactant: nothing (and no rates from absent gases).
  const double none[5] = {0.0, 0.0, 0.0, 0.0, 1.0};
  EXPECT_EQ(k::charGasificationHoisted(cp, charDh, 1200.0, none, mC0, mC0).mdotC, 0.0);
  EXPECT_EQ(k::charGasificationHoisted(cp, charDh, 1200.0, pBars[0], 0.0, mC0).mdotC, 0.0);
  const double inert[3] = {0.0, 0.6, 0.4};
  const auto o = k::ocReductionHoisted(op, ocDh, 1200.0, m, inert, 2.0, 3.0);
  EXPECT_EQ(o.nR4 + o.nR5, 0.0);
  EXPECT_EQ(o.conversion, k::ocReduction(op, 1200.0, m, inert, 2.0, 3.0).conversion);
}
