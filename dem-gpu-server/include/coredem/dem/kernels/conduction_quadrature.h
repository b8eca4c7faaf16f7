#pragma once
/// @file
/// Globally adaptive Gauss–Kronrod (G7/K15) quadrature usable in DEM_HD code: no recursion,
/// no heap, a fixed-capacity interval list on the stack. Used by the gas-lens conduction
/// integral (docs/physics.md §3.3 [C]: "adaptive Simpson or Gauss–Kronrod with a relative tolerance
/// ≤ 1e-8").
///
/// Algorithm (QUADPACK QAG style): keep a list of sub-intervals with their K15 estimate and
/// error estimate |K15 − G7|; bisect the interval with the largest error until the summed
/// error is ≤ max(absTol, relTol·|I|) or the capacity is reached. Nodes and weights are
/// the standard 15-point Kronrod extension of the 7-point Gauss–Legendre rule (exact for
/// polynomials of degree ≤ 22 on one interval).

#include <cmath>

#include <coredem/dem/kernels/common.h>

namespace coredem::dem::kernels {

/// Capacity of the interval list (max number of sub-intervals).
inline constexpr int kGkMaxIntervals = 64;

struct QuadratureResult {
  double value;   ///< integral estimate
  double error;   ///< summed error estimate (|K15 − G7| per interval)
  int intervals;  ///< number of sub-intervals used
  bool converged; ///< error ≤ requested tolerance
};

/// One G7/K15 panel on [a, b]; returns the K15 value and writes |K15 − G7| to err.
template <typename F>
DEM_HD double gaussKronrod15(const F& f, double a, double b, double& err) {
  constexpr double xgk[8] = {
      0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
      0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
      0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
      0.207784955007898467600689403773245, 0.0};
  constexpr double wgk[8] = {
      0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
      0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
      0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
      0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
  constexpr double wg[4] = {
      0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
      0.381830050505118944950369775488975, 0.417959183673469387755102040816327};
  const double c = 0.5 * (a + b);
  const double h = 0.5 * (b - a);
  const double fc = f(c);
  double resK = wgk[7] * fc;
  double resG = wg[3] * fc;
  for (int j = 0; j < 7; ++j) {
    const double dx = h * xgk[j];
    const double s = f(c - dx) + f(c + dx);
    resK += wgk[j] * s;
    if (j % 2 == 1) {
      resG += wg[j / 2] * s;
    }
  }
  err = std::fabs((resK - resG) * h);
  return resK * h;
}

/// Adaptive integral of f over [a, b] to max(absTol, relTol·|I|).
template <typename F>
DEM_HD QuadratureResult integrateAdaptive(const F& f, double a, double b, double relTol,
                                          double absTol = 0.0) {
  double lo[kGkMaxIntervals];
  double hi[kGkMaxIntervals];
  double val[kGkMaxIntervals];
  double err[kGkMaxIntervals];
  int n = 1;
  lo[0] = a;
  hi[0] = b;
  val[0] = gaussKronrod15(f, a, b, err[0]);
  double total = val[0];
  double totalErr = err[0];
  while (true) {
    const double tol = std::fmax(absTol, relTol * std::fabs(total));
    if (totalErr <= tol) {
      return {total, totalErr, n, true};
    }
    if (n >= kGkMaxIntervals) {
      return {total, totalErr, n, false};
    }
    int worst = 0;
    for (int k = 1; k < n; ++k) {
      if (err[k] > err[worst]) {
        worst = k;
      }
    }
    const double mid = 0.5 * (lo[worst] + hi[worst]);
    double e1 = 0.0;
    double e2 = 0.0;
    const double v1 = gaussKronrod15(f, lo[worst], mid, e1);
    const double v2 = gaussKronrod15(f, mid, hi[worst], e2);
    // Recompute the sums instead of updating them incrementally (no drift).
    lo[n] = mid;
    hi[n] = hi[worst];
    val[n] = v2;
    err[n] = e2;
    hi[worst] = mid;
    val[worst] = v1;
    err[worst] = e1;
    ++n;
    total = 0.0;
    totalErr = 0.0;
    for (int k = 0; k < n; ++k) {
      total += val[k];
      totalErr += err[k];
    }
  }
}

} // namespace coredem::dem::kernels
