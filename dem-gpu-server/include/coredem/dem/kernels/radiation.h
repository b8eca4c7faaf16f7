#pragma once
/// @file
/// Particle radiation with a continuum environment temperature (docs/physics.md §3.4, seed Eqs.
/// 27–28; Zhou, Yu & Zulli 2009).
///
///   (27) Q_rad,i = e_p,i σ A_p,i (T_env,i⁴ − T_p,i⁴),   A_p,i = π d_p,i²       W, into i
///   (28) T_env,i = ε_g,Ω T_g,Ω + (1 − ε_g,Ω) T̄_p,Ω
///
/// Two definitions of T̄_p,Ω (docs/physics.md §3.4):
///  (a) CellMeanIncludingSelf (MFiX `des_thermo_rad.f`): arithmetic mean of all particles whose
///      centroid is in the CFD cell of i, including i. The DEM step uses this one (heat.h).
///  (b) NeighbourMeanExcludingSelf (Zhou/Kratos, literal seed Eq. 28): mean over the neighbours
///      j ≠ i within 1.5 d_p,i of i; T_env = T_g if none. Used by the verification solutions
///      (verification/analytic.h) only; the DEM step does not offer it.
/// The caller accumulates the sum and the count of the chosen set; the kernels below turn
/// them into T_env and Q_rad.

#include <cmath>

#include <coredem/dem/kernels/common.h>

namespace coredem::dem::kernels {

/// Stefan–Boltzmann constant, W/(m² K⁴) (CODATA 2018).
inline constexpr double kStefanBoltzmann = 5.670374419e-8;

enum class RadiationEnvironment : int {
  CellMeanIncludingSelf = 0,     ///< (a) MFiX
  NeighbourMeanExcludingSelf = 1 ///< (b) Zhou / Kratos
};

/// T_env (Eq. 28), K. sumTp/count: sum and number of the particle temperatures of the set
/// chosen by the variant (count includes i for (a), excludes i for (b)). count == 0 → T_g.
DEM_HD double radiationEnvironmentTemperature(double epsG, double tG, double sumTp, int count) {
  if (count <= 0) {
    return tG;
  }
  const double meanTp = sumTp / static_cast<double>(count);
  return epsG * tG + (1.0 - epsG) * meanTp;
}

/// Radiative heat into the particle, W (Eq. 27). emissivity −, dP m, temperatures K.
DEM_HD double radiationHeat(double emissivity, double dP, double tEnv, double tP) {
  constexpr double pi = 3.141592653589793;
  const double area = pi * dP * dP;
  const double e2 = tEnv * tEnv;
  const double p2 = tP * tP;
  // T_env⁴ − T_p⁴ = (T_env² − T_p²)(T_env² + T_p²) avoids cancellation near equilibrium.
  return emissivity * kStefanBoltzmann * area * ((tEnv - tP) * (tEnv + tP)) * (e2 + p2);
}

} // namespace coredem::dem::kernels
