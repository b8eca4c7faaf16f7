#pragma once
/// @file
/// Cell sources for the CFD, accumulated over the DEM sub-steps and averaged — docs/physics.md §1.1
/// and §5 [C] (MFiX explicit coupling): per sub-step s and cell c
///   V_s,c = Σ_{i∈c} V_p,i,   K_c = Σ_{i∈c} β_i V_p,i/(1−ε),   (K U)_c = Σ_{i∈c} β_i V_p,i/(1−ε)
///   v_i
/// and after n_sub sub-steps ε_g = 1 − ⟨V_s⟩/V_c, K_sl = ⟨K⟩/V_c, K_sl·U_s = ⟨K U⟩/V_c.
/// The gas drag source is then I_gs = K_sl u_g − K_sl·U_s (implicit in u_g).

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/vec3.h"

namespace coredem::dem::kernels {

/// One particle's contribution to its cell in one sub-step.
struct CellContribution {
  double solidVolume; ///< V_p (m³)
  double kCoeff;      ///< β V_p/(1−ε) (kg/s)
  Vec3 kVel;          ///< β V_p/(1−ε) v (kg m/s²)
};

DEM_HD CellContribution cellContribution(double volume, double kCoeff, Vec3 v) {
  return CellContribution{volume, kCoeff, kCoeff * v};
}

/// Per-cell running sums over sub-steps.
struct CellAccumulator {
  double solidVolume;
  double kCoeff;
  Vec3 kVel;
};

DEM_HD void accumulate(CellAccumulator& acc, const CellContribution& c) {
  acc.solidVolume += c.solidVolume;
  acc.kCoeff += c.kCoeff;
  acc.kVel += c.kVel;
}

/// Averaged sources of one cell after nSub sub-steps.
struct CellAverages {
  double epsG; ///< -
  double kSl;  ///< kg/m³/s
  Vec3 kSlUs;  ///< kg/m²/s²
};

DEM_HD CellAverages averageSources(const CellAccumulator& acc, int nSub, double cellVolume) {
  const double w = 1.0 / (static_cast<double>(nSub) * cellVolume);
  return CellAverages{1.0 - acc.solidVolume * w, acc.kCoeff * w, w * acc.kVel};
}

} // namespace coredem::dem::kernels
