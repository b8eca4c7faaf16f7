#pragma once
/// @file
/// NASA 7-coefficient thermodynamic polynomials (docs/physics.md §3.5, Appendix A) for the
/// species of the CLG model, plus consistent molar masses.
///
///   C_p/R  = a1 + a2 T + a3 T² + a4 T³ + a5 T⁴
///   H/(RT) = a1 + a2 T/2 + a3 T²/3 + a4 T³/4 + a5 T⁴/5 + a6/T     (H includes H°_f, Eq. 30)
///   S/R    = a1 ln T + a2 T + a3 T²/2 + a4 T³/3 + a5 T⁴/4 + a7       (p° = 1 bar)
///
/// Coefficients: Burcat's database as shipped with MFiX (`model/thermochemical/BURCAT.THR`),
/// transcribed in docs/physics.md Appendix A. Units: T in K, molar quantities per mol, SI.
///
/// Interval choice: the interval [tMin, tMax) that contains T; at a break point the upper
/// interval is used (same as reference/nasa.py for the two-range species). Outside the data
/// range the first / last interval is extrapolated [C] (device code cannot throw; host code
/// can check nasa7InRange() first).

#include <cmath>

#include <coredem/dem/kernels/common.h>

namespace coredem::dem::kernels {

/// Universal gas constant, J/(mol K) (CODATA 2018, exact).
inline constexpr double kGasConstant = 8.314462618;
/// Standard reference temperature of Eq. 30, K.
inline constexpr double kTref = 298.15;

/// Species with thermodynamic data. The first five are the CFD gas species (see GasSpecies).
enum class Species : int { CO = 0, CO2, H2, H2O, N2, C, Fe2O3, Fe3O4, Al2O3, Count };
inline constexpr int kSpeciesCount = static_cast<int>(Species::Count);

/// Gas species carried by the CFD participant, in this order (indices into Y arrays).
enum class GasSpecies : int { CO = 0, CO2 = 1, H2 = 2, H2O = 3, N2 = 4, Count = 5 };
inline constexpr int kGasSpeciesCount = static_cast<int>(GasSpecies::Count);

DEM_HD constexpr Species toSpecies(GasSpecies g) {
  return static_cast<Species>(static_cast<int>(g));
}
DEM_HD constexpr int idx(GasSpecies g) {
  return static_cast<int>(g);
}

/// One polynomial interval.
struct Nasa7Interval {
  double tMin; ///< K
  double tMax; ///< K
  double a[7];
};

/// Up to three intervals, sorted by temperature.
struct Nasa7Data {
  int n;
  Nasa7Interval iv[3];
};

/// Atomic masses (kg/mol, IUPAC conventional values). [C] Molar masses are built from these
/// so that every reaction balances to round-off; they agree with docs/physics.md §6 to ≤ 2e-6
/// kg/mol (Fe2O3 159.687 vs 159.688, Fe3O4 231.531 vs 231.533 g/mol; the rounded table values do
/// not balance R4/R5 by 1e-3 g/mol).
inline constexpr double kAtomC = 12.011e-3;
inline constexpr double kAtomH = 1.008e-3;
inline constexpr double kAtomO = 15.999e-3;
inline constexpr double kAtomN = 14.007e-3;
inline constexpr double kAtomFe = 55.845e-3;
inline constexpr double kAtomAl = 26.982e-3;

/// Molar mass, kg/mol.
DEM_HD constexpr double molarMass(Species s) {
  switch (s) {
  case Species::CO:
    return kAtomC + kAtomO;
  case Species::CO2:
    return kAtomC + 2.0 * kAtomO;
  case Species::H2:
    return 2.0 * kAtomH;
  case Species::H2O:
    return 2.0 * kAtomH + kAtomO;
  case Species::N2:
    return 2.0 * kAtomN;
  case Species::C:
    return kAtomC;
  case Species::Fe2O3:
    return 2.0 * kAtomFe + 3.0 * kAtomO;
  case Species::Fe3O4:
    return 3.0 * kAtomFe + 4.0 * kAtomO;
  case Species::Al2O3:
    return 2.0 * kAtomAl + 3.0 * kAtomO;
  default:
    return 0.0;
  }
}
DEM_HD constexpr double molarMass(GasSpecies g) {
  return molarMass(toSpecies(g));
}

/// Coefficient table (docs/physics.md Appendix A; Burcat/MFiX).
// clang-format off
DEM_HD constexpr Nasa7Data nasa7Data(Species s) {
  switch (s) {
  case Species::CO:
    return {2,
            {{200.0, 1000.0, {3.5795335, -6.1035369e-4, 1.0168143e-6, 9.0700586e-10, -9.0442449e-13, -14344.086, 3.5084093}},
             {1000.0, 6000.0, {3.0484859, 1.3517281e-3, -4.8579405e-7, 7.8853644e-11, -4.6980746e-15, -14266.117, 6.0170977}},
             {}}};
  case Species::CO2:
    return {2,
            {{200.0, 1000.0, {2.3568130, 8.9841299e-3, -7.1220632e-6, 2.4573008e-9, -1.4288548e-13, -48371.971, 9.9009035}},
             {1000.0, 6000.0, {4.6365111, 2.7414569e-3, -9.9589759e-7, 1.6038666e-10, -9.1619857e-15, -49024.904, -1.9348955}},
             {}}};
  case Species::H2:
    return {2,
            {{200.0, 1000.0, {2.34433112, 7.98052075e-3, -1.9478151e-5, 2.01572094e-8, -7.37611761e-12, -917.935173, 0.683010238}},
             {1000.0, 6000.0, {2.93286575, 8.26608026e-4, -1.46402364e-7, 1.54100414e-11, -6.888048e-16, -813.065581, -1.02432865}},
             {}}};
  case Species::H2O:
    return {2,
            {{200.0, 1000.0, {4.1986352, -2.0364017e-3, 6.5203416e-6, -5.4879269e-9, 1.771968e-12, -30293.726, -0.84900901}},
             {1000.0, 6000.0, {2.6770389, 2.9731816e-3, -7.7376889e-7, 9.4433514e-11, -4.2689991e-15, -29885.894, 6.88255}},
             {}}};
  case Species::N2:
    return {2,
            {{200.0, 1000.0, {3.53100528, -1.23660988e-4, -5.02999433e-7, 2.43530612e-9, -1.40881235e-12, -1046.97628, 2.96747038}},
             {1000.0, 6000.0, {2.95257637, 1.3969004e-3, -4.92631603e-7, 7.86010195e-11, -4.60755204e-15, -923.948688, 5.87188762}},
             {}}};
  case Species::C:
    return {2,
            {{200.0, 1000.0, {-0.303744539, 4.36036227e-3, 1.98268825e-6, -6.43472598e-9, 2.9960132e-12, -109.458288, 1.08301475}},
             {1000.0, 6000.0, {1.5982807, 1.43065097e-3, -5.09435105e-7, 8.64401302e-11, -5.3434953e-15, -745.940284, -9.30332005}},
             {}}};
  case Species::Fe2O3:
    return {3,
            {{298.15, 960.0, {0.152218166, 6.7075704e-2, -1.12860954e-4, 9.93356662e-8, -3.27580975e-11, -101344.092, -6.15024507}},
             {960.0, 1000.0, {17.2604275, -1.25903995e-4, 0.0, 0.0, 0.0, -104248.826, -88.6853598}},
             {1000.0, 1800.0, {16.5731962, 1.7213654e-3, -1.9239601e-6, 9.30825106e-10, -1.669031e-13, -104043.235, -85.0919728}}}};
  case Species::Fe3O4:
    return {3,
            {{298.15, 850.0, {4.84450959, 4.39051578e-2, 5.24676763e-5, -2.20801809e-7, 1.74856371e-10, -138015.344, -23.8418082}},
             {850.0, 1000.0, {80.1656571, -9.93203597e-2, 4.41610956e-5, 0.0, 0.0, -161839.98, -429.480191}},
             {1000.0, 1870.0, {84.2362953, -0.135489942, 1.09817004e-4, -3.8784718e-8, 5.22775385e-12, -161060.501, -442.636234}}}};
  case Species::Al2O3:
    return {3,
            {{200.0, 1000.0, {-8.3764894, 0.109323686, -2.25731157e-4, 2.29482917e-7, -9.22595951e-11, -202316.511, 29.4431298}},
             {1000.0, 1200.0, {2.60994032, 3.76023553e-2, -4.63474789e-5, 2.7330168e-8, -6.21672705e-12, -203702.845, -18.325849}},
             {1200.0, 2327.0, {12.230695, 3.61303142e-3, -1.36449202e-6, 5.02558143e-10, -6.84618788e-14, -205837.976, -65.8728585}}}};
  default: return {0, {}};
  }
}
// clang-format on

/// Index of the interval used at temperature T (see file comment for the rule).
DEM_HD constexpr int nasa7IntervalIndex(const Nasa7Data& d, double T) {
  int i = 0;
  while (i + 1 < d.n && T >= d.iv[i].tMax) {
    ++i;
  }
  return i;
}

/// True if T lies inside the tabulated range of species s.
DEM_HD constexpr bool nasa7InRange(Species s, double T) {
  const Nasa7Data d = nasa7Data(s);
  return d.n > 0 && T >= d.iv[0].tMin && T <= d.iv[d.n - 1].tMax;
}

/// Molar heat capacity C_p, J/(mol K).
DEM_HD double nasa7CpMolar(Species s, double T) {
  const Nasa7Data d = nasa7Data(s);
  const double* a = d.iv[nasa7IntervalIndex(d, T)].a;
  return kGasConstant * (a[0] + T * (a[1] + T * (a[2] + T * (a[3] + T * a[4]))));
}

/// Molar enthalpy H (formation enthalpy included, Eq. 30), J/mol.
DEM_HD double nasa7EnthalpyMolar(Species s, double T) {
  const Nasa7Data d = nasa7Data(s);
  const double* a = d.iv[nasa7IntervalIndex(d, T)].a;
  return kGasConstant *
         (T * (a[0] + T * (a[1] / 2.0 + T * (a[2] / 3.0 + T * (a[3] / 4.0 + T * a[4] / 5.0)))) +
          a[5]);
}

/// Molar entropy at p° = 1 bar, J/(mol K).
DEM_HD double nasa7EntropyMolar(Species s, double T) {
  const Nasa7Data d = nasa7Data(s);
  const double* a = d.iv[nasa7IntervalIndex(d, T)].a;
  return kGasConstant * (a[0] * std::log(T) +
                         T * (a[1] + T * (a[2] / 2.0 + T * (a[3] / 3.0 + T * a[4] / 4.0))) + a[6]);
}

/// Standard molar Gibbs energy G° = H − T S°, J/mol.
DEM_HD double nasa7GibbsMolar(Species s, double T) {
  return nasa7EnthalpyMolar(s, T) - T * nasa7EntropyMolar(s, T);
}

/// Specific heat capacity, J/(kg K).
DEM_HD double nasa7CpMass(Species s, double T) {
  return nasa7CpMolar(s, T) / molarMass(s);
}

} // namespace coredem::dem::kernels
