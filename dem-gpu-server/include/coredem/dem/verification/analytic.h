#pragma once
/// @file
/// Analytic and reference solutions for the thermochemistry verification suite
/// (docs/physics.md §8; seed Section 3; MFiX `legacy_tests/dem-tests`, Musser 2011 property set).
/// Host-only helpers (they use std::vector); the physics comes from the DEM_HD kernels, so the
/// reference and the simulation share the sub-model formulas but not the time integration.
///
///  §8.0/8.1/8.2  two-particle exchange dT_i/dt = a (T_j − T_i), dT_j/dt = b (T_i − T_j):
///      T_i(t) = [b T_i0 + a T_j0 + a (T_i0 − T_j0) e^(−(a+b)t)]/(a+b)
///      T_j(t) = [b T_i0 + a T_j0 − b (T_i0 − T_j0) e^(−(a+b)t)]/(a+b)
///      contact: a = G/(m_i C_i), G = 4 k_i k_j/(k_i+k_j) r_c;   lens: G = κ_g I
///  §8.3  T_p(t) = T_g − (T_g − T_p0) exp(−h A t/(m C_p))
///  §8.4  radiation: classical RK4 of dT_i/dt = C_i (T_env,i⁴ − T_i⁴) with a small step
///  §8.5  A(g) + 2B(s) → C(g) + D(s) at constant extent rate ω while B remains:
///      m(t) = m0 − (−r_B)(1 − M_D/(2M_B)) t,   t ≤ t_end = m0 X_B0/(−r_B),   −r_B = 2 M_B ω
///      X_B = (m0 X_B0 − (−r_B) t)/m,  X_D = (m0 X_D0 + M_D ω t)/m,  X_I = m0 X_I0/m

#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

#include <coredem/common/check.h>
#include <coredem/dem/kernels/conduction_contact.h>
#include <coredem/dem/kernels/conduction_gas_lens.h>
#include <coredem/dem/kernels/convection.h>
#include <coredem/dem/kernels/radiation.h>

namespace coredem::dem::verification {

/// Unit conversions of the CGS MFiX inputs (docs/physics.md §8.0).
inline constexpr double kCalPerSCmKToWPerMK = 418.4; ///< cal/(s cm K) → W/(m K)
inline constexpr double kCalPerGKToJPerKgK = 4184.0; ///< cal/(g K) → J/(kg K)

/// Solid material of a verification particle.
struct Material {
  double rho;              ///< kg/m³
  double k;                ///< W/(m K)
  double cp;               ///< J/(kg K)
  double emissivity = 0.8; ///< −
};

/// Musser/MFiX particle "A" (phase 1, d = 3.0 mm) and "B" (phase 2, d = 3.6 mm), §8.0.
inline Material musserMaterialA() {
  return {420.0, 0.131453 * kCalPerSCmKToWPerMK, 0.191204 * kCalPerGKToJPerKgK, 0.8};
}
inline Material musserMaterialB() {
  return {8850.0, 0.002008 * kCalPerSCmKToWPerMK, 0.013145 * kCalPerGKToJPerKgK, 0.8};
}
/// Gas conductivity of the particle–fluid–particle test, W/(m K).
inline constexpr double kMusserLensGasConductivity = 1.239e-4 * kCalPerSCmKToWPerMK;
/// Gas of the convection test (ρ, μ, κ, C_p; T and ε are set by the case).
inline kernels::GasState musserConvectionGas(double tG, double eps) {
  return {1.1854, 1.8603e-5, 1.2396e-4 * kCalPerSCmKToWPerMK, 0.23878 * kCalPerGKToJPerKgK,
          tG,     eps};
}

/// Volume of a sphere of diameter d, m³.
inline double sphereVolume(double d) {
  constexpr double pi = 3.141592653589793;
  return pi / 6.0 * d * d * d;
}
/// Mass of a sphere of diameter d, kg.
inline double sphereMass(const Material& m, double d) {
  return m.rho * sphereVolume(d);
}

struct TwoTemperatures {
  double t1; ///< K
  double t2; ///< K
};

/// Exact solution of the linear two-particle exchange (§8.0), K.
inline TwoTemperatures twoParticleExchange(double a, double b, double t10, double t20, double t) {
  const double e = std::exp(-(a + b) * t);
  const double base = b * t10 + a * t20;
  return {(base + a * (t10 - t20) * e) / (a + b), (base - b * (t10 - t20) * e) / (a + b)};
}

/// Final common temperature T_∞ = (m1C1 T10 + m2C2 T20)/(m1C1 + m2C2) = (b T10 + a T20)/(a+b).
inline double twoParticleEquilibrium(double a, double b, double t10, double t20) {
  return (b * t10 + a * t20) / (a + b);
}

struct ExchangeCoefficients {
  double a;           ///< s⁻¹, G/(m_1 C_1)
  double b;           ///< s⁻¹, G/(m_2 C_2)
  double conductance; ///< G, W/K
};

/// Contact conduction coefficients (§8.1) for diameters d1, d2 (m) at centre distance l (m).
inline ExchangeCoefficients contactConductionCoefficients(double d1, const Material& m1, double d2,
                                                          const Material& m2, double l) {
  const double g = kernels::contactConductance(m1.k, m2.k, 0.5 * d1, 0.5 * d2, l);
  return {g / (sphereMass(m1, d1) * m1.cp), g / (sphereMass(m2, d2) * m2.cp), g};
}

/// Gas-lens conduction coefficients (§8.2). Throws if the quadrature did not converge.
inline ExchangeCoefficients gasLensCoefficients(double d1, const Material& m1, double d2,
                                                const Material& m2, double l, double kG,
                                                const kernels::GasLensParams& p = {}) {
  const kernels::GasLensIntegral in = kernels::gasLensIntegral(p, 0.5 * d1, 0.5 * d2, l);
  COREDEM_CHECK(in.converged,
                "gas-lens integral did not reach relTol={} (estimate {}, error {}); use a looser "
                "relTol or check the geometry (d1={}, d2={}, l={})",
                p.relTol, in.value, in.error, d1, d2, l);
  const double g = kG * in.value;
  return {g / (sphereMass(m1, d1) * m1.cp), g / (sphereMass(m2, d2) * m2.cp), g};
}

/// A pair of fixed particles exchanging heat by conduction (§8.1, §8.2).
struct TwoParticleCase {
  double d1; ///< m
  Material m1;
  double d2; ///< m
  Material m2;
  double l;   ///< centre distance, m
  double t10; ///< K
  double t20; ///< K
};

/// MFiX-CC (§8.1): A at y = 1.499864 mm (298.15 K), B at y = 4.799731 mm (453.15 K).
inline TwoParticleCase mfixContactConductionCase() {
  return {
      3.0e-3, musserMaterialA(), 3.6e-3, musserMaterialB(), (0.4799731 - 0.1499864) * 1e-2, 298.15,
      453.15};
}

/// Seed contact variants (§8.1): A (3.0 mm, 373.15 K) and material B of diameter d2 at
/// 278.15 K, overlapping by `overlap` (m).
inline TwoParticleCase seedContactConductionCase(double d2, double overlap) {
  return {3.0e-3, musserMaterialA(), d2, musserMaterialB(), 1.5e-3 + 0.5 * d2 - overlap, 373.15,
          278.15};
}

/// MFiX-PFP (§8.2): A at y = 11.50 mm (298.15 K), B at y = 14.98 mm (453.15 K), gap 0.18 mm.
inline TwoParticleCase mfixLensCase() {
  return {3.0e-3, musserMaterialA(), 3.6e-3, musserMaterialB(), (1.498 - 1.150) * 1e-2, 298.15,
          453.15};
}

/// Seed gas-lens variants (§8.2): A (3.0 mm, 373.15 K), B (3.6 mm, 278.15 K), surface gap
/// `gap` (m; negative = overlap).
inline TwoParticleCase seedLensCase(double gap) {
  return {3.0e-3, musserMaterialA(), 3.6e-3, musserMaterialB(), 3.3e-3 + gap, 373.15, 278.15};
}

/// Contact coefficients of a case.
inline ExchangeCoefficients contactConductionCoefficients(const TwoParticleCase& c) {
  return contactConductionCoefficients(c.d1, c.m1, c.d2, c.m2, c.l);
}

/// Lens coefficients of a case (gas conductivity κ_g of §8.0 unless given).
inline ExchangeCoefficients gasLensCoefficients(const TwoParticleCase& c,
                                                const kernels::GasLensParams& p = {},
                                                double kG = kMusserLensGasConductivity) {
  return gasLensCoefficients(c.d1, c.m1, c.d2, c.m2, c.l, kG, p);
}

/// Gas voidage of the MFiX convection cell (4 × 4 × 0.36 cm with one 3.6-mm particle), §8.3.
inline double mfixConvectionCellVoidage() {
  return 1.0 - sphereVolume(3.6e-3) / (0.04 * 0.04 * 0.0036);
}

/// Convection rate constant h A_p/(m C_p), s⁻¹ (§8.3).
inline double convectionCoefficient(const kernels::ConvectionParams& p, const kernels::GasState& g,
                                    double d, const Material& m, double slip) {
  const kernels::ConvectionResult r = kernels::convection(p, g, d, slip, g.T);
  return r.conductance / (sphereMass(m, d) * m.cp);
}

/// T_p(t) of a single particle in a gas at fixed T_g (§8.3), K.
inline double convectionTemperature(double tG, double tP0, double coefficient, double t) {
  return tG - (tG - tP0) * std::exp(-coefficient * t);
}

/// Radiation constant C = e σ π d²/(m C_p), K⁻³ s⁻¹ (§8.4).
inline double radiationConstant(const Material& m, double d) {
  constexpr double pi = 3.141592653589793;
  return m.emissivity * kernels::kStefanBoltzmann * pi * d * d / (sphereMass(m, d) * m.cp);
}

/// Two particles in one cell exchanging radiation with a gas held at T_g (§8.4).
struct RadiationCase {
  double d1;
  Material m1;
  double d2;
  Material m2;
  double epsG; ///< cell gas fraction
  double tG;   ///< K
  double t10;  ///< K
  double t20;  ///< K
  kernels::RadiationEnvironment environment = kernels::RadiationEnvironment::CellMeanIncludingSelf;
};

/// The MFiX radiation case (§8.4): A at 298.15 K, B at 453.15 K, T_g = 400 K, both in one
/// 1.5 × 1.0 × 0.36 cm cell.
inline RadiationCase mfixRadiationCase(
    kernels::RadiationEnvironment env = kernels::RadiationEnvironment::CellMeanIncludingSelf) {
  const double d1 = 3.0e-3;
  const double d2 = 3.6e-3;
  const double epsG = 1.0 - (sphereVolume(d1) + sphereVolume(d2)) / (0.015 * 0.010 * 0.0036);
  return {d1, musserMaterialA(), d2, musserMaterialB(), epsG, 400.0, 298.15, 453.15, env};
}

/// Right-hand side dT/dt of the radiation case, K/s.
inline TwoTemperatures radiationRates(const RadiationCase& c, double t1, double t2) {
  double env1 = 0.0;
  double env2 = 0.0;
  if (c.environment == kernels::RadiationEnvironment::CellMeanIncludingSelf) {
    env1 = env2 = kernels::radiationEnvironmentTemperature(c.epsG, c.tG, t1 + t2, 2);
  } else {
    env1 = kernels::radiationEnvironmentTemperature(c.epsG, c.tG, t2, 1);
    env2 = kernels::radiationEnvironmentTemperature(c.epsG, c.tG, t1, 1);
  }
  const double q1 = kernels::radiationHeat(c.m1.emissivity, c.d1, env1, t1);
  const double q2 = kernels::radiationHeat(c.m2.emissivity, c.d2, env2, t2);
  return {q1 / (sphereMass(c.m1, c.d1) * c.m1.cp), q2 / (sphereMass(c.m2, c.d2) * c.m2.cp)};
}

/// RK4 reference (seed Eqs. 47–48) at the requested output times (ascending, ≥ 0), with
/// step dt (the last step before an output time is shortened to land on it exactly).
inline std::vector<TwoTemperatures>
radiationReferenceRK4(const RadiationCase& c, std::span<const double> times, double dt = 1.0e-3) {
  COREDEM_CHECK(dt > 0.0, "radiation RK4 step must be positive (got {} s)", dt);
  std::vector<TwoTemperatures> out;
  out.reserve(times.size());
  double t = 0.0;
  double x1 = c.t10;
  double x2 = c.t20;
  for (const double target : times) {
    COREDEM_CHECK(target >= t,
                  "radiation RK4 output times must be ascending and >= 0 (got {} after {})", target,
                  t);
    while (t < target) {
      const double remaining = target - t;
      const bool last = remaining <= dt * (1.0 + 1e-9);
      const double h = last ? remaining : dt;
      const TwoTemperatures k1 = radiationRates(c, x1, x2);
      const TwoTemperatures k2 = radiationRates(c, x1 + 0.5 * h * k1.t1, x2 + 0.5 * h * k1.t2);
      const TwoTemperatures k3 = radiationRates(c, x1 + 0.5 * h * k2.t1, x2 + 0.5 * h * k2.t2);
      const TwoTemperatures k4 = radiationRates(c, x1 + h * k3.t1, x2 + h * k3.t2);
      x1 += h / 6.0 * (k1.t1 + 2.0 * k2.t1 + 2.0 * k3.t1 + k4.t1);
      x2 += h / 6.0 * (k1.t2 + 2.0 * k2.t2 + 2.0 * k3.t2 + k4.t2);
      t = last ? target : t + h;
    }
    out.push_back({x1, x2});
  }
  return out;
}

/// The reaction A(g) + 2B(s) → C(g) + D(s) with inert I (§8.5), constant extent rate.
struct ReactionCase {
  double m0;     ///< kg
  double xB0;    ///< −
  double xD0;    ///< −
  double xI0;    ///< −
  double molarA; ///< kg/mol
  double molarB; ///< kg/mol
  double molarC; ///< kg/mol
  double molarD; ///< kg/mol
  double omega;  ///< mol/s while B remains
};

/// MFiX reactive-chemistry case (§8.5): d = 3 mm, ρ = 2500 kg/m³, X_B0 = X_I0 = 0.5,
/// M_A = 25, M_B = 15, M_C = 30, M_D = 25 g/mol, ω = 3.927e-4 mol/s.
inline ReactionCase mfixReactionCase() {
  return {2500.0 * sphereVolume(3.0e-3), 0.5, 0.0, 0.5, 25e-3, 15e-3, 30e-3, 25e-3, 3.927e-4};
}

struct ReactionState {
  double m;  ///< kg
  double xB; ///< −
  double xD; ///< −
  double xI; ///< −
};

/// −r_B = 2 M_B ω, kg/s.
inline double reactionSolidConsumption(const ReactionCase& c) {
  return 2.0 * c.molarB * c.omega;
}

/// Time at which B is exhausted, s.
inline double reactionEndTime(const ReactionCase& c) {
  return c.m0 * c.xB0 / reactionSolidConsumption(c);
}

/// Analytic particle state at time t (corrected Eqs. 53–56).
inline ReactionState reactionAnalytic(const ReactionCase& c, double t) {
  const double rB = reactionSolidConsumption(c);
  const double tc = std::fmin(t, reactionEndTime(c));
  const double rD = c.molarD * c.omega;
  const double m = c.m0 - rB * (1.0 - c.molarD / (2.0 * c.molarB)) * tc;
  const double xB = t >= reactionEndTime(c) ? 0.0 : (c.m0 * c.xB0 - rB * tc) / m;
  return {m, xB, (c.m0 * c.xD0 + rD * tc) / m, c.m0 * c.xI0 / m};
}

/// Shrinking core with a constant rate coefficient k (s⁻¹): dξ/dt = k (1 − ξ)^(2/3) gives
/// 1 − ξ(t) = (1 − k t/3)³ for t < 3/k and 0 afterwards (docs/physics.md §6.1 char with constant
/// gas, §6.3 grain model with constant gas). For pure-carbon char, 1 − ξ = m_C/m_C0 and the
/// diameter of a constant-density particle is d0 (1 − k t/3).
inline double shrinkingCoreUnreacted(double k, double t) {
  const double s = 1.0 - k * t / 3.0;
  return s > 0.0 ? s * s * s : 0.0;
}

/// Time at which a pure-carbon particle reaches d = threshold · d0 under a constant rate k.
inline double shrinkingCoreRemovalTime(double k, double threshold) {
  return 3.0 * (1.0 - threshold) / k;
}

} // namespace coredem::dem::verification
