#pragma once
/// @file
/// A heterogeneous (gas–particle) reaction defined by data: stoichiometry, molar masses and a
/// constant or Arrhenius rate. Used by the reactive-chemistry verification case
/// (docs/physics.md §8.5: A(g) + 2B(s) → C(g) + D(s), ω = 3.927e-4 mol/s while X_B > 0) and by any
/// case that declares its own reactions.
///
///   extent rate (mol of reaction per s, per particle):
///     Constant:   ω = A
///     Arrhenius:  ω = A T_p^β exp(−E/(R T_p))
///     optionally ω ·= C_g^order for one gas reactant (C_g = ρ_g Y/M, mol/m³)
///   availability: ω = 0 if any solid reactant is exhausted; and, for a step dt > 0,
///     ω ≤ m_k / (|ν_k| M_k dt) for every solid reactant k, so no solid mass goes negative.
///   species sources (kg/s): ṁ_k = ν_k M_k ω (solid → particle, Eq. 31; gas → R_gn of Eq. 5)
///   heat into the particle: Q_rxn = −ΔH ω (§3.5), ΔH given in J/mol of reaction.
///
/// Mass is conserved to round-off when Σ ν_k M_k = 0 (checked by heterogeneousMassImbalance).
///
/// Rate laws are a model family (kernels/model_list.h) chosen per reaction
/// (HeterogeneousReaction::law, from `reactions[].rate.law`): a law's coefficients (A, β, E) are
/// the reaction's data, not `models:` keys, so the laws declare no parameters. Adding one: its
/// model struct below (name, doc, Params, params(), `evaluate(const Params&, reaction, T_p)`
/// returning ω before the order and availability factors, mol/s), its name appended to RateLaws
/// (the others' ids, and so earlier configuration hashes, stay), and its spelling in the
/// `reactions:` reader and Configure's RateLaw.

#include <cmath>

#include <coredem/dem/kernels/common.h>
#include <coredem/dem/kernels/model_list.h>

namespace coredem::dem::kernels {

inline constexpr int kMaxReactionTerms = 6;

enum class ReactionPhase : int { Gas = 0, Solid = 1 };
/// A rate law's id (its position in RateLaws; the configuration hash uses it); case-file names
/// in the registry (coredem/dem/models.h, rateLawModels()).
enum class RateLaw : int { Constant = 0, Arrhenius = 1 };

struct HeterogeneousReaction {
  int n = 0;                                   ///< number of terms
  ReactionPhase phase[kMaxReactionTerms] = {}; ///< phase of each term
  int index[kMaxReactionTerms] = {};           ///< index into particle solids / cell gas species
  double nu[kMaxReactionTerms] = {};           ///< mol per mol of reaction (< 0 reactants)
  double molarMass[kMaxReactionTerms] = {};    ///< kg/mol
  RateLaw law = RateLaw::Constant;
  double A = 0.0;     ///< Constant: mol/s; Arrhenius: mol/s · K^−β · (m³/mol)^order
  double beta = 0.0;  ///< temperature exponent, −
  double E = 0.0;     ///< activation energy, J/mol
  int orderTerm = -1; ///< term whose gas concentration enters the rate (−1: none)
  double order = 0.0; ///< its reaction order, −
  double dH = 0.0;    ///< heat of reaction, J per mol of reaction (> 0 endothermic)
};

/// ω = A (mol/s).
struct ConstantRate {
  static constexpr const char* name = "constant";
  static constexpr const char* doc = "ω = A (mol/s)";
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }

  DEM_HD static double evaluate(const Params&, const HeterogeneousReaction& r, double) {
    return r.A;
  }
};

/// ω = A T_p^β exp(−E/(R T_p)) (mol/s).
struct ArrheniusRate {
  static constexpr const char* name = "arrhenius";
  static constexpr const char* doc = "ω = A T^β exp(−E/(R T)) (× C_g^order)";
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }

  DEM_HD static double evaluate(const Params&, const HeterogeneousReaction& r, double tP) {
    // T^β exp(−E/(RT)) as one exp() (β = 0: no log).
    const double arg = -r.E / (8.314462618 * tP);
    return r.A * std::exp(r.beta == 0.0 ? arg : r.beta * std::log(tP) + arg);
  }
};

/// The rate laws, in id order (the registration line).
using RateLaws = ModelList<ConstantRate, ArrheniusRate>;

template <class Law>
constexpr RateLaw rateLaw() {
  return static_cast<RateLaw>(modelId<Law, RateLaws>);
}
static_assert(rateLaw<ConstantRate>() == RateLaw::Constant);
static_assert(rateLaw<ArrheniusRate>() == RateLaw::Arrhenius);

/// The family's dispatch: Dispatch<RateLawFamily, RateLaws> calls the reaction's law (the laws
/// take their coefficients from the reaction: default Params).
struct RateLawFamily {
  template <class Law>
  DEM_HD static double evaluate(const HeterogeneousReaction& r, const double& tP) {
    return Law::evaluate(typename Law::Params{}, r, tP);
  }
};

/// Rate before availability limits, mol/s. gasConc: cell concentrations (mol/m³) indexed by
/// the gas-species indices of the terms (may be null when orderTerm < 0).
DEM_HD double heterogeneousRate(const HeterogeneousReaction& r, double tP, const double* gasConc) {
  double w = Dispatch<RateLawFamily, RateLaws>::call(static_cast<int>(r.law), r, tP);
  if (r.orderTerm >= 0) {
    const double c = gasConc[r.index[r.orderTerm]];
    w *= c > 0.0 ? (r.order == 1.0 ? c : std::pow(c, r.order)) : 0.0;
  }
  return w;
}

/// Apply the availability limits (see file comment). solidMass: kg of each particle solid
/// species (m X_k), indexed by the solid-term indices. dt ≤ 0 disables the step limit.
DEM_HD double limitByAvailability(const HeterogeneousReaction& r, double w, const double* solidMass,
                                  double dt) {
  for (int k = 0; k < r.n; ++k) {
    if (r.phase[k] != ReactionPhase::Solid || !(r.nu[k] < 0.0)) {
      continue;
    }
    const double avail = solidMass[r.index[k]];
    if (!(avail > 0.0)) {
      return 0.0;
    }
    if (dt > 0.0) {
      const double wMax = avail / (-r.nu[k] * r.molarMass[k] * dt);
      w = w < wMax ? w : wMax;
    }
  }
  return w;
}

/// Extent rate with availability limits, mol/s.
DEM_HD double heterogeneousExtentRate(const HeterogeneousReaction& r, double tP,
                                      const double* gasConc, const double* solidMass, double dt) {
  return limitByAvailability(r, heterogeneousRate(r, tP, gasConc), solidMass, dt);
}

/// Accumulate species mass rates ν_k M_k ω (kg/s) into solidRate / gasRate (by term index).
DEM_HD void addHeterogeneousSources(const HeterogeneousReaction& r, double w, double* solidRate,
                                    double* gasRate) {
  for (int k = 0; k < r.n; ++k) {
    const double mdot = r.nu[k] * r.molarMass[k] * w;
    if (r.phase[k] == ReactionPhase::Solid) {
      solidRate[r.index[k]] += mdot;
    } else {
      gasRate[r.index[k]] += mdot;
    }
  }
}

/// Σ ν_k M_k, kg per mol of reaction (0 for a balanced reaction).
DEM_HD double heterogeneousMassImbalance(const HeterogeneousReaction& r) {
  double s = 0.0;
  for (int k = 0; k < r.n; ++k) {
    s += r.nu[k] * r.molarMass[k];
  }
  return s;
}

/// Heat into the particle from this reaction, W.
DEM_HD double heterogeneousHeat(const HeterogeneousReaction& r, double w) {
  return -r.dH * w;
}

} // namespace coredem::dem::kernels
