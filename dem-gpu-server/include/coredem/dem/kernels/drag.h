#pragma once
/// @file
/// Drag laws (docs/physics.md §2.2): the registry of the family and its dispatch. The engine calls
/// particleDragCoefficient() with the law chosen by `models: {drag: ...}`.
///
/// Adding a drag law: its kernel header (a model struct: name, doc, Params, params(), and
/// `DEM_HD static double coefficient(const Params&, eps, ρ_g, μ_g, d_p, V_p, |Δu|)` returning
/// β V_p/(1−ε) in kg/s for ε already clipped), its name in DragLaws below (appended: the ids of
/// the others, and so earlier configuration hashes, stay), its test and its docs/case-schema.md
/// rows. Its `models:` value and parameter keys, their validation, hashing and copy into the
/// engine come from the declaration (coredem/dem/models.h; docs/architecture.md).

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/drag_gidaspow.h"
#include "coredem/dem/kernels/drag_koch_hill.h"
#include "coredem/dem/kernels/drag_single_laws.h"
#include "coredem/dem/kernels/drag_syamlal_beetstra.h"
#include "coredem/dem/kernels/drag_voidage_function.h"
#include "coredem/dem/kernels/model_list.h"

namespace coredem::dem::kernels {

/// The drag laws, in id order (the registration line).
using DragLaws = ModelList<GidaspowDrag, WenYuDrag, ErgunDrag, GidaspowBlendDrag, DiFeliceDrag,
                           RongDrag, SyamlalObrienDrag, BeetstraDrag, KochHillDrag>;

/// A drag law's id (its position in DragLaws; the configuration hash uses it). The default has
/// a name; any law's id is dragLaw<Law>().
enum class DragLaw : int {
  Gidaspow = 0 ///< Ergun (ε ≤ 0.8) / Wen–Yu (drag_gidaspow.h), the default
};

template <class Law>
constexpr DragLaw dragLaw() {
  return static_cast<DragLaw>(modelId<Law, DragLaws>);
}
static_assert(dragLaw<GidaspowDrag>() == DragLaw::Gidaspow);

/// The parameters of every drag law (plain data, passed by value into the kernels).
struct DragParams {
  DragLaw law = DragLaw::Gidaspow;
  ParamPack<DragLaws> laws{}; ///< each law's Params (laws.of<Law>())
  double epsMin = 0.35; ///< ε clip of every law (docs/physics.md §1.1 [C], dem.eps_min_drag)
};

/// The family's dispatch: Dispatch<DragFamily, DragLaws> calls the chosen law.
struct DragFamily {
  template <class Law>
  DEM_HD static double evaluate(const DragParams& p, const double& eps, const double& rhoG,
                                const double& muG, const double& dp, const double& volume,
                                const double& slip) {
    return Law::coefficient(p.laws.template of<Law>(), eps, rhoG, muG, dp, volume, slip);
  }
};

/// Per-particle drag coefficient β V_p/(1−ε) (kg/s) of the chosen law, for the gas fraction
/// epsCell of the particle's cell (clipped to ε_min, and below 1: the dilute limit), ρ_g (kg/m³),
/// μ_g (Pa s), d_p (m), V_p (m³), |u_g − v| (m/s). The force is dragForce(coefficient, u_g, v) =
/// coefficient·(u_g − v) (N).
DEM_HD double particleDragCoefficient(const DragParams& p, double epsCell, double rhoG, double muG,
                                      double dp, double volume, double slip) {
  double eps = epsCell < p.epsMin ? p.epsMin : epsCell;
  if (eps >= 1.0)
    eps = 1.0 - 1e-12; // no particle volume in the cell: dilute limit
  return Dispatch<DragFamily, DragLaws>::call(static_cast<int>(p.law), p, eps, rhoG, muG, dp,
                                              volume, slip);
}

} // namespace coredem::dem::kernels
