#pragma once
/// @file
/// Particle–gas convective heat transfer (docs/physics.md §3.1, seed Eqs. 19–21).
///
///   (19) Q_gp,i = h_i A_p,i (T_g − T_p,i),   A_p,i = π d_p,i²      W, gas → particle
///   (20) h_i    = Nu_i κ_g / d_p,i                                   W/(m² K)
///   (21) Li & Mason (2000), as used by Zhou, Yu & Zulli (2009), n = 3.5:
///        Nu = 2 + 0.6 εⁿ Re^0.5 Pr^(1/3)                           Re < 200
///        Nu = 2 + 0.5 εⁿ Re^0.5 Pr^(1/3) + 0.02 εⁿ Re^0.8 Pr^(1/3)  200 ≤ Re < 1500
///        Nu = 2 + 4.5e-5 εⁿ Re^1.8                                 Re ≥ 1500
///   Ranz–Marshall (MFiX `des_thermo_conv.f`, option): Nu = 2 + 0.6 Re^0.5 Pr^(1/3)
///   Gunn (1978, option): Nu = (7 − 10ε + 5ε²)(1 + 0.7 Re^0.2 Pr^(1/3))
///                             + (1.33 − 2.4ε + 1.2ε²) Re^0.7 Pr^(1/3); Deen et al. (2014) and
///   Tavassoli et al. (2015), options: the same form with their coefficients (nusselt_gunn.h)
///   Pr = μ_g C_p,g / κ_g.
///   Re_p = ε ρ_g d_p |u_g − v_p| / μ_g (default, same Re as the Gidaspow drag, docs/physics.md
///   §3.1 [C])
///        or ρ_g d_p |u_g − v_p| / μ_g (reynoldsWithVoidage = false, Kratos form).
///   ε is clipped below at epsMin (docs/physics.md §1.1 [C], 0.35) in the Nusselt evaluation.
///
/// Coupling split (docs/architecture.md): per particle the conductance G_i = h_i A_p,i (W/K). The
/// gas energy equation receives −Q_gp,c = −(H_c T_g − (H T_p)_c) with
///   H_c = Σ_{i∈c} G_i / V_c  (W/(m³ K), implicit coefficient on T_g)
///   (H T_p)_c = Σ_{i∈c} G_i T_p,i / V_c  (W/m³, explicit part),
/// which equals (1/V_c) Σ Q_gp,i exactly when T_g is the cell value (PCM).
///
/// Adding a Nusselt correlation: its kernel header (a model struct as nusselt_li_mason.h: name,
/// doc, Params, params(), `voidageFactor(const Params&, ε, n)`, the part that depends on the gas
/// state only, and `evaluate(const Params&, Re, Pr^⅓, voidageFactor)` returning Nu), its name in
/// NusseltModels below (appended: the others' ids, and so earlier configuration hashes, stay),
/// its test and its docs/case-schema.md rows. Its `models: {convection: …}` value and parameter
/// keys (`convection.<model>.<key>`), their validation, hashing and copy into the engine come
/// from the declaration (coredem/dem/models.h).

#include <cmath>

#include <coredem/dem/kernels/common.h>
#include <coredem/dem/kernels/model_list.h>
#include <coredem/dem/kernels/nusselt_gunn.h>
#include <coredem/dem/kernels/nusselt_li_mason.h>
#include <coredem/dem/kernels/nusselt_ranz_marshall.h>

namespace coredem::dem::kernels {

/// The Nusselt correlations, in id order (the registration line).
using NusseltModels =
    ModelList<LiMasonNusselt, RanzMarshallNusselt, GunnNusselt, DeenNusselt, TavassoliNusselt>;

/// A Nusselt correlation's id (its position in NusseltModels; the configuration hash uses it);
/// case-file names in the registry (coredem/dem/models.h, nusseltModels()). Any correlation's id
/// is nusseltModel<M>().
enum class NusseltModel : int { LiMason = 0, RanzMarshall = 1 };

template <class M>
constexpr NusseltModel nusseltModel() {
  return static_cast<NusseltModel>(modelId<M, NusseltModels>);
}
static_assert(nusseltModel<LiMasonNusselt>() == NusseltModel::LiMason);
static_assert(nusseltModel<RanzMarshallNusselt>() == NusseltModel::RanzMarshall);

struct ConvectionParams {
  NusseltModel model = NusseltModel::LiMason;
  double voidageExponent = 3.5;      ///< n in Eq. 21 (Li & Mason: 3.5 dilute, 4.75 dense)
  bool reynoldsWithVoidage = true;   ///< Re_p with ε (default) or without
  double epsMin = 0.35;              ///< lower clip of ε_g in Re and εⁿ (0 disables)
  ParamPack<NusseltModels> models{}; ///< each correlation's Params (models.of<M>())
};

/// Gas state seen by a particle (cell of its centroid, PCM), SI.
struct GasState {
  double rho; ///< kg/m³
  double mu;  ///< Pa s
  double k;   ///< W/(m K)
  double cp;  ///< J/(kg K)
  double T;   ///< K
  double eps; ///< gas volume fraction at the particle, −
};

/// Particle Reynolds number, −.
DEM_HD double particleReynolds(double rhoG, double muG, double dP, double slip, double eps,
                               bool withVoidage) {
  const double re = rhoG * dP * slip / muG;
  return withVoidage ? eps * re : re;
}

/// Prandtl number, −.
DEM_HD double prandtl(double muG, double cpG, double kG) {
  return muG * cpG / kG;
}

/// The family's dispatch on the gas-state factor: Dispatch<NusseltVoidageFamily, NusseltModels>.
struct NusseltVoidageFamily {
  template <class M>
  DEM_HD static double evaluate(const ConvectionParams& p, const double& eps) {
    return M::voidageFactor(p.models.template of<M>(), eps, p.voidageExponent);
  }
};

/// The family's dispatch on the Nusselt number: Dispatch<NusseltFamily, NusseltModels>.
struct NusseltFamily {
  template <class M>
  DEM_HD static double evaluate(const ConvectionParams& p, const double& re, const double& pr13,
                                const double& en) {
    return M::evaluate(p.models.template of<M>(), re, pr13, en);
  }
};

/// The factors of the Nusselt number that depend only on the gas state (constant over a CFD
/// step in a PCM cell): computed once per cell and step instead of once per particle and
/// sub-step (a pow and a cbrt fewer per particle). nusseltFromFactors() gives bitwise the value
/// of nusseltLiMason()/nusseltRanzMarshall() (same operations in the same order).
struct NusseltFactors {
  double eps;  ///< ε clipped at epsMin, −
  double en;   ///< the correlation's voidage factor (Li–Mason: εⁿ), −
  double pr13; ///< Pr^(1/3), −
};

DEM_HD NusseltFactors nusseltFactors(const ConvectionParams& p, const GasState& g) {
  const double eps = g.eps > p.epsMin ? g.eps : p.epsMin;
  const double en =
      Dispatch<NusseltVoidageFamily, NusseltModels>::call(static_cast<int>(p.model), p, eps);
  return {eps, en, std::cbrt(prandtl(g.mu, g.cp, g.k))};
}

/// Nusselt number from the cell factors and the particle Reynolds number, −.
DEM_HD double nusseltFromFactors(const ConvectionParams& p, const NusseltFactors& f, double re) {
  return Dispatch<NusseltFamily, NusseltModels>::call(static_cast<int>(p.model), p, re, f.pr13,
                                                      f.en);
}

/// Nusselt number for the chosen model, from the slip speed |u_g − v_p| (m/s).
DEM_HD double nusselt(const ConvectionParams& p, const GasState& g, double dP, double slip) {
  const NusseltFactors f = nusseltFactors(p, g);
  const double re = particleReynolds(g.rho, g.mu, dP, slip, f.eps, p.reynoldsWithVoidage);
  return nusseltFromFactors(p, f, re);
}

/// Result of the convection kernel for one particle.
struct ConvectionResult {
  double conductance; ///< G = h A_p, W/K
  double heat;        ///< Q_gp = G (T_g − T_p), W, into the particle (Eq. 19)
};

/// Convective heat exchange of one particle (Eqs. 19–21). dP in m, slip in m/s, tP in K.
DEM_HD ConvectionResult convection(const ConvectionParams& p, const GasState& g, double dP,
                                   double slip, double tP) {
  const double nu = nusselt(p, g, dP, slip);
  const double h = nu * g.k / dP;
  constexpr double pi = 3.141592653589793;
  const double area = pi * dP * dP;
  const double conductance = h * area;
  return {conductance, conductance * (g.T - tP)};
}

/// convection() with the cell's Nusselt factors precomputed (nusseltFactors(p, g)); bitwise the
/// same result.
DEM_HD ConvectionResult convectionFromFactors(const ConvectionParams& p, const NusseltFactors& f,
                                              const GasState& g, double dP, double slip,
                                              double tP) {
  const double re = particleReynolds(g.rho, g.mu, dP, slip, f.eps, p.reynoldsWithVoidage);
  const double nu = nusseltFromFactors(p, f, re);
  const double h = nu * g.k / dP;
  constexpr double pi = 3.141592653589793;
  const double area = pi * dP * dP;
  const double conductance = h * area;
  return {conductance, conductance * (g.T - tP)};
}

/// Cell accumulator of the implicit/explicit heat exchange for the CFD (W/(m³K), W/m³).
struct ConvectionCellSource {
  double H = 0.0;   ///< Σ G_i / V_c
  double HTp = 0.0; ///< Σ G_i T_p,i / V_c
};

/// Add particle i (conductance G, temperature tP) to its cell's source; invVc = 1/V_c.
DEM_HD void addConvectionToCell(ConvectionCellSource& c, double conductance, double tP,
                                double invVc) {
  c.H += conductance * invVc;
  c.HTp += conductance * tP * invVc;
}

/// Heat from gas to particles in a cell, W/m³ (Q_gp,c of Eq. 3), from the split form.
DEM_HD double cellConvectionHeat(const ConvectionCellSource& c, double tG) {
  return c.H * tG - c.HTp;
}

} // namespace coredem::dem::kernels
