#pragma once
/// @file
/// Drag-law dispatch (docs/physics.md §2.2): the engine calls particleDragCoefficient() with the
/// law chosen by `models: {drag: ...}` (registry: coredem/dem/models.h). Adding a drag law: its
/// kernel header (one function returning β V_p/(1−ε) in kg/s), an enumerator and a case here,
/// one registry row in models.cpp, its test (docs/architecture.md).

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/drag_gidaspow.h"

namespace coredem::dem::kernels {

/// Drag laws (enum values are stable: the configuration hash uses them).
enum class DragLaw : int {
  Gidaspow = 0 ///< Ergun (ε ≤ 0.8) / Wen–Yu (drag_gidaspow.h)
};

/// Parameters of every drag law (plain data, passed by value into the kernels).
struct DragParams {
  DragLaw law = DragLaw::Gidaspow;
  GidaspowParams gidaspow{}; ///< ε_min clip and the Ergun/Wen–Yu switch
};

/// Per-particle drag coefficient β V_p/(1−ε) (kg/s) of the chosen law, for the gas fraction
/// epsCell of the particle's cell, ρ_g (kg/m³), μ_g (Pa s), d_p (m), V_p (m³), |u_g − v| (m/s).
/// The force is dragForce(coefficient, u_g, v) = coefficient·(u_g − v) (N).
DEM_HD double particleDragCoefficient(const DragParams& p, double epsCell, double rhoG, double muG,
                                      double dp, double volume, double slip) {
  switch (p.law) {
  case DragLaw::Gidaspow:
  default:
    return gidaspowParticleCoefficient(p.gidaspow, epsCell, rhoG, muG, dp, volume, slip);
  }
}

} // namespace coredem::dem::kernels
