#pragma once
/// @file
/// Particle energy equation (docs/physics.md §3, seed Eq. 18) and the heat of heterogeneous
/// reactions (§3.5). Particles are isothermal (lumped, Bi ≪ 1).
///
///   (18) m_i C_p,i dT_p,i/dt = Σ_j Q_pp,ij + Σ_j Q_pfp,ij + Q_gp,i + Q_rad,i + Q_rxn,i
///        Q_rxn,i = − Σ_{r∈het} ΔH_r(T_p,i) ṅ_r,i     (ṅ_r,i mol of reaction r per s)
///
/// [C] The whole heat of heterogeneous reactions goes to the particle (MFiX fracDH = 1).
/// Time integration [C]: explicit Euler with Δt_DEM (MFiX default DES_INTG_METHOD='EULER').

#include <coredem/dem/kernels/common.h>
#include <coredem/dem/kernels/nasa7.h>

namespace coredem::dem::kernels {

/// Heat sources of one particle, W (all "into the particle").
struct ParticleHeatSources {
  double contactConduction = 0.0; ///< Σ_j Q_pp,ij (conduction_contact.h)
  double lensConduction = 0.0;    ///< Σ_j Q_pfp,ij (conduction_gas_lens.h)
  double convection = 0.0;        ///< Q_gp,i (convection.h)
  double radiation = 0.0;         ///< Q_rad,i (radiation.h)
  double reaction = 0.0;          ///< Q_rxn,i (heterogeneousReactionHeat)
};

/// Right-hand side of Eq. 18, W.
DEM_HD double particleHeatRate(const ParticleHeatSources& s) {
  return s.contactConduction + s.lensConduction + s.convection + s.radiation + s.reaction;
}

/// dT_p/dt, K/s. m in kg, cp in J/(kg K).
DEM_HD double particleTemperatureRate(const ParticleHeatSources& s, double m, double cp) {
  return particleHeatRate(s) / (m * cp);
}

/// Explicit Euler update of T_p over dt (s), K.
DEM_HD double particleTemperatureEuler(double tP, const ParticleHeatSources& s, double m, double cp,
                                       double dt) {
  return tP + dt * particleTemperatureRate(s, m, cp);
}

/// Q_rxn = −Σ_r ΔH_r ṅ_r, W. dH: J/mol of reaction (at T_p); nDot: mol/s; n reactions.
DEM_HD double heterogeneousReactionHeat(const double* dH, const double* nDot, int n) {
  double q = 0.0;
  for (int r = 0; r < n; ++r) {
    q -= dH[r] * nDot[r];
  }
  return q;
}

/// Mixture specific heat of a particle from its species mass fractions, J/(kg K):
/// C_p = Σ_k X_k c_p,k(T) with NASA-7 data (an option; the verification cases use constant C_p).
DEM_HD double particleCpFromSpecies(const Species* species, const double* massFraction, int n,
                                    double tP) {
  double cp = 0.0;
  for (int k = 0; k < n; ++k) {
    cp += massFraction[k] * nasa7CpMass(species[k], tP);
  }
  return cp;
}

} // namespace coredem::dem::kernels
