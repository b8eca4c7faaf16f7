#pragma once
/// @file
/// Particle–fluid–particle conduction through a gas "lens" (docs/physics.md §3.3, seed Eqs. 24–26;
/// Rong & Horio 1999 as modified in MFiX `des_thermo_cond.f`).
///
///   (24) Q_pfp,ij = κ_g (T_j − T_i) I,   I = ∫_{R_in}^{R_out} 2π r dr / max(gap(r), s_min)
///        gap(r) = l − √(R_L² − r²) − √(R_S² − r²),   R_L = max(R_i,R_j), R_S = min(R_i,R_j)
///        lens radius R_lens = (1 + FLPC) R_L  (lens built around the larger sphere, FLPC = 0.2)
///   (25) R_in  = 0 if l ≥ R_i + R_j (no contact), r_c (Eq. 23) if in contact
///   (26) R_out = √(R_lens² − ((R_lens² − R_S² + l²)/(2 l))²)
///        no pfp if the lens does not reach the smaller sphere (l ≥ R_lens + R_S).
///        [C] R_out = R_S once l² ≤ R_lens² − R_S² (the intersection plane is at or beyond the
///        small sphere's centre, so its whole facing hemisphere is inside the lens). Eq. 26
///        agrees at the switch, so R_out stays continuous in l. This only matters for size
///        ratios R_S/R_L < 0.19 (FLPC = 0.2).
///   s_min: minimum conduction distance; MFiX code default DES_MIN_COND_DIST = 1e-6 m [C].
///
/// Numerics [C] (target: 1e-8 relative or better):
///  * gasLensIntegral() evaluates I in closed form (substitution t = √(R_L² − r²) + √(R_S² − r²)
///    turns the integrand into a rational function of t; derivation at the function). Its
///    rounding error is below kGasLensClosedFormRelError = 1e-13 relative over the DEM range;
///    it costs one square root, one or two logarithms and a few divisions per pair.
///  * gasLensIntegralEqualRadii() is the equal-radii case written in gaps (the pair pass's
///    common case: no square root, one or two divisions), within kGasLensEqualRadiiRelDiff =
///    1e-14 of gasLensIntegral(). The logarithms of both are gasLensLog()/gasLensLog1p(),
///    fdlibm's kernel inline (≤ kGasLensLog1pUlp = 2 ulp).
///  * gasLensIntegralReference() is the former per-pair adaptive quadrature, kept as the
///    independent reference for the tests: the gap without cancellation as
///      gap(r) = g0 + (r − R_in)(r + R_in) [1/(a + a0) + 1/(b + b0)],
///    a = √(R_L² − r²), b = √(R_S² − r²), (a0, b0) = (a, b) at R_in, g0 = l − a0 − b0
///    (g0 = 0 in contact, the surface gap l − R_L − R_S otherwise); the clipped part where
///    gap < s_min in closed form, π(r*² − R_in²)/s_min, with r* the root of gap(r*) = s_min
///    (safeguarded Newton); the rest by adaptive Gauss–Kronrod (conduction_quadrature.h), in
///    contact with r = R_in + e^u (removes the near-logarithmic singularity at R_in), otherwise
///    with u = ln(g0 + c0 r²), c0 = 1/(2R_L) + 1/(2R_S), for the same reason when g0 is small.
///
/// The result depends on (R_L, R_S, l) only, so Q_ij = −Q_ji bitwise.

#include <cmath>
#include <cstdint>
#include <cstring>

#include <coredem/dem/kernels/common.h>
#include <coredem/dem/kernels/conduction_contact.h>
#include <coredem/dem/kernels/conduction_quadrature.h>

namespace coredem::dem::kernels {

struct GasLensParams {
  double lensFraction = 0.2;     ///< FLPC: lens radius = (1 + FLPC) R_L, −
  double minSeparation = 1.0e-6; ///< s_min, m (> 0: the integral diverges at contact otherwise)
  /// Relative tolerance: of gasLensIntegralReference()'s quadrature; gasLensIntegral() reports
  /// `converged = false` if its rounding bound (kGasLensClosedFormRelError) exceeds it.
  double relTol = 1.0e-10;
};

/// Limits of the lens integral.
struct GasLensGeometry {
  bool active;  ///< false if the lens does not reach the smaller sphere
  bool contact; ///< l < R_i + R_j
  double rIn;   ///< m (Eq. 25)
  double rOut;  ///< m (Eq. 26)
};

DEM_HD GasLensGeometry gasLensGeometry(const GasLensParams& p, double ri, double rj, double l) {
  const double big = ri > rj ? ri : rj;
  const double small = ri > rj ? rj : ri;
  const double rLens = (1.0 + p.lensFraction) * big;
  const bool contact = l < big + small;
  if (!(l < rLens + small)) {
    return {false, contact, 0.0, 0.0};
  }
  // [C] Once the lens/small-sphere intersection plane lies at or beyond the small sphere's
  // centre (l² ≤ R_lens² − R_S²), its whole facing hemisphere is inside the lens: R_out = R_S.
  // Eq. 26 alone would shrink R_out towards 0 there; this keeps R_out continuous in l.
  const double rOut = (l * l <= (rLens - small) * (rLens + small))
                          ? small
                          : intersectionCircleRadius(rLens, small, l);
  const double rIn = contact ? intersectionCircleRadius(big, small, l) : 0.0;
  return {rOut > rIn, contact, rIn, rOut};
}

struct GasLensIntegral {
  double value;   ///< I, m
  double error;   ///< error bound (closed form) or estimate (reference quadrature), m
  bool converged; ///< error within relTol
};

/// The lens integral I of Eq. 24 (m) by adaptive Gauss–Kronrod to p.relTol: the reference the
/// closed form gasLensIntegral() is tested against (unit tests only; ~25× its cost).
DEM_HD GasLensIntegral gasLensIntegralReference(const GasLensParams& p, double ri, double rj,
                                                double l) {
  constexpr double pi = 3.141592653589793;
  if (!(p.minSeparation > 0.0) || !(p.lensFraction >= 0.0)) {
    return {0.0, 0.0, false}; // invalid parameters (the case parser rejects them)
  }
  const GasLensGeometry geo = gasLensGeometry(p, ri, rj, l);
  if (!geo.active) {
    return {0.0, 0.0, true};
  }
  const double big = ri > rj ? ri : rj;
  const double small = ri > rj ? rj : ri;
  const double sMin = p.minSeparation;
  const double rIn = geo.rIn;
  const double rOut = geo.rOut;
  double a0 = big;
  double b0 = small;
  double g0 = l - big - small;
  if (geo.contact) {
    a0 = std::sqrt((big - rIn) * (big + rIn));
    b0 = std::sqrt((small - rIn) * (small + rIn));
    // Intersection plane between the centres (the normal case): the surfaces meet at R_in.
    g0 = (l * l >= (big - small) * (big + small)) ? 0.0 : l - a0 - b0;
  }
  // gap as a function of d = r − R_in (d ≥ 0), cancellation-free.
  auto gapOf = [=](double d) {
    const double r = rIn + d;
    const double a = std::sqrt(std::fmax((big - r) * (big + r), 0.0));
    const double b = std::sqrt(std::fmax((small - r) * (small + r), 0.0));
    return g0 + d * (r + rIn) * (1.0 / (a + a0) + 1.0 / (b + b0));
  };
  const double dOut = rOut - rIn;
  // Root d* of gap(d*) = s_min (gap increases with r).
  double dStar = 0.0;
  if (gapOf(dOut) <= sMin) {
    return {pi * dOut * (rOut + rIn) / sMin, 0.0, true};
  }
  if (gapOf(0.0) < sMin) {
    double lo = 0.0;
    double hi = dOut;
    double d = 0.5 * (lo + hi);
    for (int it = 0; it < 100; ++it) {
      const double r = rIn + d;
      const double g = gapOf(d) - sMin;
      if (g > 0.0) {
        hi = d;
      } else {
        lo = d;
      }
      const double a = std::sqrt(std::fmax((big - r) * (big + r), 0.0));
      const double b = std::sqrt(std::fmax((small - r) * (small + r), 0.0));
      const double slope = r / a + r / b; // d gap / d r
      double next = d - g / slope;
      if (!(next > lo && next < hi)) {
        next = 0.5 * (lo + hi);
      }
      if (std::fabs(next - d) <= 1e-15 * rOut || hi - lo <= 1e-15 * rOut) {
        d = next;
        break;
      }
      d = next;
    }
    dStar = d;
  }
  // Closed-form clipped part on [R_in, R_in + d*].
  const double clipped = pi * dStar * (2.0 * rIn + dStar) / sMin;
  QuadratureResult q{};
  if (geo.contact) {
    // r = R_in + e^u:  ∫ 2π r e^u / max(gap, s_min) du
    auto f = [=](double u) {
      const double d = std::exp(u);
      const double g = gapOf(d);
      return 2.0 * pi * (rIn + d) * d / (g > sMin ? g : sMin);
    };
    q = integrateAdaptive(f, std::log(dStar), std::log(dOut), p.relTol);
  } else {
    // v = r², then u = ln(g0 + c0 v) with c0 = 1/(2R_L) + 1/(2R_S) (gap ≈ g0 + c0 v near the
    // axis):  I = π ∫ dv / max(gap, s_min) = (π/c0) ∫ e^u / max(gap, s_min) du, whose integrand
    // is ≈ 1 wherever the gap is small.
    const double c0 = 0.5 / big + 0.5 / small;
    auto f = [=](double u) {
      const double eu = std::exp(u);
      const double v = std::fmax((eu - g0) / c0, 0.0);
      const double g = gapOf(std::sqrt(v));
      return pi / c0 * eu / (g > sMin ? g : sMin);
    };
    q = integrateAdaptive(f, std::log(g0 + c0 * dStar * dStar), std::log(g0 + c0 * dOut * dOut),
                          p.relTol);
  }
  return {clipped + q.value, q.error, q.converged};
}

/// Relative bound on the rounding error of the closed form gasLensIntegral() over the DEM
/// range (R_S/R_L in [0.1, 1], overlaps up to 5 % of R_S, s_min 1e-10..1e-5 m for R of
/// 1e-4..1e-2 m). Each term of the closed form is formed to a few ulp and the terms cancel by
/// at most a factor ~10 there (t − D²/t³ ≥ 0.3 t for R_S/R_L ≥ 0.1), so ~1e-14; stated with
/// margin. Observed: ≤ 1.7e-15 against 40-digit quadrature (24 points in the unit tests,
/// 1,500 random points offline), ≤ 6e-14 against gasLensIntegralReference at relTol 1e-12
/// over a 10,800-point sweep (tests/unit/thermochem/conduction_test.cpp). Below the range the
/// cancellation grows like R_L/R_S (a sphere against a wall-like partner of 10⁴ R: ~1e-12).
inline constexpr double kGasLensClosedFormRelError = 1.0e-13;

namespace detail {

/// Bits of a double and back (host: memcpy, device: the intrinsics).
DEM_HD_FORCEINLINE std::uint64_t doubleBits(double x) {
#if defined(__CUDA_ARCH__)
  return static_cast<std::uint64_t>(__double_as_longlong(x));
#else
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
#endif
}

DEM_HD_FORCEINLINE double doubleFromBits(std::uint64_t b) {
#if defined(__CUDA_ARCH__)
  return __longlong_as_double(static_cast<long long>(b));
#else
  double x;
  std::memcpy(&x, &b, sizeof x);
  return x;
#endif
}

/// k ln 2 + ln(1 + f) + lo for f in [√2/2 − 1, √2 − 1] and a small correction lo (ln(1 + c/u)
/// ≈ c/u of a rounded argument u), as fdlibm's e_log.c/k_log.h (Sun Microsystems 1993): with
/// s = f/(2 + f), ln(1 + f) = 2 atanh s = f − f²/2 + s (f²/2 + R(s²)), R a degree-14 Remez fit
/// of 2 atanh(s)/s − 2 − … (error below 2^−58.45), ln 2 split into a 32-bit head and its tail.
/// Pure arithmetic (inlined, no library call); below 1 ulp (fdlibm's bound for ln). Callers
/// without a correction pass lo = −0.0, which the compiler drops (x + (−0) = x for every x).
DEM_HD_FORCEINLINE double logKernel(double f, double k, double lo) {
  constexpr double ln2Hi = 6.93147180369123816490e-01; // 0x3fe62e42fee00000
  constexpr double ln2Lo = 1.90821492927058770002e-10; // 0x3dea39ef35793c76
  constexpr double lg1 = 6.666666666666735130e-01;
  constexpr double lg2 = 3.999999999940941908e-01;
  constexpr double lg3 = 2.857142874366239149e-01;
  constexpr double lg4 = 2.222219843214978396e-01;
  constexpr double lg5 = 1.818357216161805012e-01;
  constexpr double lg6 = 1.531383769920937332e-01;
  constexpr double lg7 = 1.479819860511658591e-01;
  const double s = f / (2.0 + f);
  const double z = s * s;
  const double w = z * z;
  const double t1 = w * (lg2 + w * (lg4 + w * lg6));
  const double t2 = z * (lg1 + w * (lg3 + w * (lg5 + w * lg7)));
  const double r = t2 + t1;
  const double hfsq = 0.5 * f * f;
  return k * ln2Hi - ((hfsq - (s * (hfsq + r) + (k * ln2Lo + lo))) - f);
}

} // namespace detail

/// ln u for normal u ≥ 1 (finite): u = 2^k m, m in [√2/2, √2) (fdlibm's split: the mantissa
/// plus 0x95f64… carries into the exponent exactly when it is above ≈ √2), then the kernel. Pure
/// arithmetic, below 1 ulp (fdlibm's bound).
DEM_HD_FORCEINLINE double gasLensLog(double u) {
  const std::uint64_t b = detail::doubleBits(u);
  const std::uint64_t mant = b & 0x000fffffffffffffULL;
  const std::uint64_t carry = (mant + 0x00095f6400000000ULL) & 0x0010000000000000ULL;
  const int k = static_cast<int>(b >> 52) - 1023 + static_cast<int>(carry >> 52);
  const double m = detail::doubleFromBits(mant | (0x3ff0000000000000ULL ^ carry));
  return detail::logKernel(m - 1.0, static_cast<double>(k), -0.0);
}

/// ln(1 + x) for 0 ≤ x < 2^1023 (finite), the logarithm of the lens integral: pure arithmetic,
/// no library call (the call made the pair loop spill every live register). Above 1, ln of the
/// rounded 1 + x (costs at most 1/2 ulp of 1 + x, i.e. 0.72 ulp of a result ≥ ln 2); up to √2 − 1
/// the kernel on f = x itself; in between on f = (1 + x)/2 − 1 with the rounding error c of
/// 1 + x (exact, Fast2Sum) added as c/(1 + x). Error bound kGasLensLog1pUlp ulp, tested against
/// log1pl over [0, 1e12] (tests/unit/thermochem/conduction_equal_radii_test.cpp).
DEM_HD_FORCEINLINE double gasLensLog1p(double x) {
  if (x > 1.0) {
    return gasLensLog(1.0 + x);
  }
  if (x <= 0.41421356237309503) {
    return detail::logKernel(x, 0.0, -0.0);
  }
  const double u = 1.0 + x;       // in (√2, 2]
  const double c = x - (u - 1.0); // exact rounding error of 1 + x
  return detail::logKernel(0.5 * u - 1.0, 1.0, c / u);
}

/// Bound on gasLensLog1p()'s and gasLensLog()'s errors in ulp of the result (observed ≤ 1.52
/// and ≤ 1.0; see gasLensLog1p()).
inline constexpr double kGasLensLog1pUlp = 2.0;

/// The lens integral I of Eq. 24 (m) in closed form. Depends only on the sorted radii and l.
///
/// With v = r², a = √(R_L² − v), b = √(R_S² − v), D = R_L² − R_S² = a² − b² and t = a + b
/// (so a − b = D/t, a = (t + D/t)/2, dv = −(t − D²/t³)/2 dt, gap = l − t):
///
///   I = π ∫ dv / max(gap, s_min) = (π/2) ∫_{t_out}^{t_in} (t − D²/t³)/(l − t) dt (+ clipped part)
///
/// a rational integrand. With g = l − t, δ = t_1 − t_2 = g_2 − g_1 (1 = the inner end: R_in,
/// or r* where the gap reaches s_min; 2 = R_out) and q = D/l², partial fractions give
///
///   I_open = (π/2) [ l (1 − q²) ln(1 + δ/g_1) − δ
///                    − q² ( l³ (t_1 + t_2) δ/(2 t_1² t_2²) + l² δ/(t_1 t_2) + l ln(1 + δ/t_2) ) ]
///
/// (equal radii: D = 0, I_open = (π/2)[l ln(g_2/g_1) − (g_2 − g_1)], i.e. ∫ 2π s ds/(l − 2s)
/// with s = √(R² − r²)). The clipped part π(r*² − R_in²)/s_min is closed too: t* = l − s_min,
/// r*² − R_in² = a_in² − a*² = (a_in − a*)(a_in + a*), a_in − a* = Δ(2 b_in − Δ)/(2 t*),
/// Δ = t_in − t* = s_min − g_in, using t_in² − D = 2 b_in t_in. Every difference is formed
/// without cancellation: g_out − g_in = (R_out² − R_in²)[1/(a_in + a_out) + 1/(b_in + b_out)],
/// 1 − q = (l² − D)/l² with l² − D = (l − R_L)(l + R_L) + R_S², the logarithms as log1p.
/// The limits follow gasLensGeometry()'s rules, as R² and chord distances from factored
/// triangle formulas (below). No iteration, no quadrature: one square root, one logarithm
/// (equal radii) or two, a few divisions.
///
/// `error` is kGasLensClosedFormRelError·I (a bound on the rounding error, not an estimate);
/// `converged` is false if that exceeds p.relTol·I, or for invalid parameters.
DEM_HD GasLensIntegral gasLensIntegral(const GasLensParams& p, double ri, double rj, double l) {
  constexpr double pi = 3.141592653589793;
  if (!(p.minSeparation > 0.0) || !(p.lensFraction >= 0.0)) {
    return {0.0, 0.0, false}; // invalid parameters (the case parser rejects them)
  }
  const double big = ri > rj ? ri : rj;
  const double small = ri > rj ? rj : ri;
  const double sMin = p.minSeparation;
  auto result = [&](double value) {
    const double err = kGasLensClosedFormRelError * value;
    return GasLensIntegral{value, err, err <= p.relTol * value};
  };
  // Limits as gasLensGeometry() (same rules), but as R² and the chord distances a = √(R_L² − R²),
  // b = √(R_S² − R²) from the factored triangle formulas, which need no square root:
  //   R_L − a_c = h (l + R_S − R_L)/(2l),  R_S − b_c = h (l + R_L − R_S)/(2l)   (h = R_L + R_S − l)
  // for the circle where two spheres cross; R_c² = (R_L − a_c)(R_L + a_c).
  const double rLens = (1.0 + p.lensFraction) * big;
  const double lMinusBig = l - big;
  if (!(l < rLens + small)) {
    return {0.0, 0.0, true}; // the lens does not reach the smaller sphere
  }
  const double half = 0.5 / l;                     // 1/(2l)
  const double dd = (big - small) * (big + small); // D = R_L² − R_S²
  // Outer end R_out (Eq. 26, or R_S once l² ≤ R_lens² − R_S²).
  double rOut2 = small * small;
  double bOut = 0.0;
  if (l * l > (rLens - small) * (rLens + small)) {
    const double lensDrop = (small - (l - rLens)) * ((l - rLens) + small) * half; // R_lens − x
    const double x = rLens - lensDrop; // plane of the lens/small-sphere circle from the big centre
    rOut2 = lensDrop * (rLens + x);
    bOut = l - x;
  }
  const double aOut = std::sqrt(dd + bOut * bOut); // a² − b² = D
  // Inner end R_in: a, b, t = a + b and the gap g = l − t there.
  double aIn = big;
  double bIn = small;
  double tIn = big + small;
  double gIn = lMinusBig - small;
  double rIn2 = 0.0;
  if (l < big + small) {
    if (!(lMinusBig + small > 0.0)) {
      return {0.0, 0.0, true}; // one sphere inside the other: R_in = R_S ≥ R_out
    }
    const double overlap = small - lMinusBig;
    const double aDrop = overlap * (lMinusBig + small) * half; // R_L − a_in
    const double bDrop = overlap * ((l - small) + big) * half; // R_S − b_in (b signed)
    aIn = big - aDrop;
    rIn2 = aDrop * (big + aIn);
    const double bSigned = small - bDrop;
    if (bSigned >= 0.0) {
      bIn = bSigned; // intersection plane between the centres: the surfaces meet at R_in
      tIn = l;
      gIn = 0.0;
    } else {
      bIn = -bSigned;
      tIn = aIn + bIn;
      gIn = l - aIn - bIn;
    }
  }
  if (!(rOut2 > rIn2)) {
    return {0.0, 0.0, true};
  }
  // g_out − g_in without cancellation.
  const double rise = (rOut2 - rIn2) * (1.0 / (aIn + aOut) + 1.0 / (bIn + bOut));
  if (gIn + rise <= sMin) {
    return result(pi * (rOut2 - rIn2) / sMin); // all clipped
  }
  // Clipped part on [R_in, r*] where gap < s_min: π (r*² − R_in²)/s_min.
  double clipped = 0.0;
  double t1 = tIn;
  double g1 = gIn;
  double delta = rise;
  if (gIn < sMin) {
    const double tStar = l - sMin;
    const double dT = sMin - gIn;
    const double aStar = 0.5 * (tStar + dd / tStar);
    clipped = pi * dT * (2.0 * bIn - dT) * (aIn + aStar) / (2.0 * tStar * sMin);
    t1 = tStar;
    g1 = sMin;
    delta = rise - dT;
  }
  // Open part on [r*, R_out] (or [R_in, R_out]).
  double open = 0.0;
  if (dd == 0.0) {
    open = l * gasLensLog1p(delta / g1) - delta; // equal radii
  } else {
    const double t2 = tIn - rise;
    const double invL2 = 4.0 * half * half; // 1/l²
    const double q = dd * invL2;
    const double oneMinusQ = (lMinusBig * (l + big) + small * small) * invL2;
    const double inv12 = 1.0 / (t1 * t2);
    open = l * (oneMinusQ * (1.0 + q)) * gasLensLog1p(delta / g1) - delta -
           (q * q) * (l * l * delta * inv12 * (0.5 * l * (t1 + t2) * inv12 + 1.0) +
                      l * gasLensLog1p(delta / t2));
  }
  return result(clipped + 0.5 * pi * open);
}

/// Per-radius constants of gasLensIntegralEqualRadii(), formed once per particle (hoisted out
/// of the pair loop).
struct GasLensEqualRadii {
  double r;      ///< R = R_L = R_S, m
  double twoR;   ///< 2R: in contact at l < 2R, m
  double rLens;  ///< (1 + FLPC) R, m
  double reach;  ///< R_lens + R: no lens at l ≥ reach, m
  double kappa;  ///< κ = R_lens² − R² = (R_lens − R)(R_lens + R), m²
  double kappaS; ///< κ/s_min, m
};

DEM_HD GasLensEqualRadii gasLensEqualRadii(const GasLensParams& p, double r) {
  const double rLens = (1.0 + p.lensFraction) * r;
  const double kappa = (rLens - r) * (rLens + r);
  return {r, r + r, rLens, rLens + r, kappa, kappa / p.minSeparation};
}

/// Relative bound on |gasLensIntegralEqualRadii() − gasLensIntegral()| (both closed forms of
/// the same integral, rounded differently) over the DEM range of
/// tests/unit/thermochem/conduction_equal_radii_test.cpp; against exact values the equal-radii
/// form keeps kGasLensClosedFormRelError (tested on the 40-digit values of conduction_test.cpp).
inline constexpr double kGasLensEqualRadiiRelDiff = 1.0e-14;

/// The lens integral I of Eq. 24 (m) for two spheres of the same radius R (p the parameters,
/// c = gasLensEqualRadii(p, R)), the pair loop's common case (a monodisperse bed), in the
/// equal-radii closed form, far shorter than gasLensIntegral()'s:
///
///   gap(r) = l − 2√(R² − r²), so r² = R² − ((l − g)/2)² at gap g, and
///   g_in  = max(l − 2R, 0)                                  (the surfaces meet in contact)
///   g_out = κ/l (κ = R_lens² − R², the lens circle), or l once l² ≤ κ (R_out = R)
///   clipped part π (r*² − R_in²)/s_min = π (s_min − g_in)(2l − g_in − s_min)/(4 s_min)
///   open part (π/2) [l ln(1 + δ/g_1) − δ],  g_1 = max(g_in, s_min),  δ = g_out − g_1
///
/// (all clipped if g_out ≤ s_min: π (g_out − g_in)(2l − g_in − g_out)/(4 s_min)). In contact
/// the clipped part is π(2l − s_min)/4 and 1 + δ/s_min = u = κ/(l s_min), so that (κ/s_min per
/// radius) I = π(2l − s_min)/4 + (π/2)[l ln u − s_min (u − 1)]; apart, likewise with u =
/// g_out/g_1 while u > 2, and closer to the reach ln(1 + δ/g_1) with g_out − g_in =
/// (R − (l − R_lens))(R_lens + (l − R))/l without cancellation. One or two
/// divisions, the logarithm (gasLensLog, gasLensLog1p), no square root. Agrees with
/// gasLensIntegral() within kGasLensEqualRadiiRelDiff, and with exact values within
/// kGasLensClosedFormRelError. Distances l ≤ R (more than half the spheres overlapping) take the
/// general function.
DEM_HD_FORCEINLINE double gasLensIntegralEqualRadii(const GasLensParams& p,
                                                    const GasLensEqualRadii& c, double l) {
  constexpr double pi = 3.141592653589793;
  if (!(p.minSeparation > 0.0) || !(p.lensFraction >= 0.0) || !(l < c.reach)) {
    return 0.0; // invalid parameters, or the lens does not reach the other sphere
  }
  if (!(l > c.r)) {
    return gasLensIntegral(p, c.r, c.r, l).value;
  }
  const double sMin = p.minSeparation;
  const bool chord = l * l > c.kappa; // R_out on the lens circle (else R_out = R, g_out = l)
  double clipped = 0.0;
  double g1 = 0.0;
  double delta = 0.0;
  if (l < c.twoR) {
    // In contact: g_in = 0. Usually g_out/s_min = κ/(l s_min) > 2: then 1 + δ/s_min is that
    // ratio, formed with one division and no rounding of 1 + x, and δ = s_min (u − 1) (u − 1 is
    // exact for u ≥ 1).
    if (chord) {
      const double u = c.kappaS / l;
      if (u > 2.0) {
        return 0.25 * pi * (2.0 * l - sMin) + 0.5 * pi * (l * gasLensLog(u) - sMin * (u - 1.0));
      }
    }
    const double gOut = chord ? c.kappa / l : l;
    if (gOut <= sMin) {
      return pi * gOut * (2.0 * l - gOut) / (4.0 * sMin); // all clipped
    }
    clipped = 0.25 * pi * (2.0 * l - sMin);
    g1 = sMin;
    delta = gOut - sMin;
  } else {
    const double gIn = l - c.twoR;
    if (chord) {
      // Apart, and far enough from the reach that u = 1 + δ/g_1 = g_out/g_1 > 2: as in contact,
      // ln u directly (u − 1 is exact; l ln u ≥ 2R ln 2 exceeds δ ≤ κ/(2R) for FLPC ≤ 0.9, so
      // l ln u − δ does not cancel).
      if (gIn < sMin) {
        const double u = c.kappaS / l;
        if (u > 2.0) {
          const double dS = sMin - gIn;
          return pi * dS * ((2.0 * l - gIn) - sMin) / (4.0 * sMin) +
                 0.5 * pi * (l * gasLensLog(u) - sMin * (u - 1.0));
        }
      } else {
        const double u = c.kappa / (l * gIn);
        if (u > 2.0) {
          return 0.5 * pi * (l * gasLensLog(u) - gIn * (u - 1.0));
        }
      }
    }
    const double rise = chord ? (c.r - (l - c.rLens)) * (c.rLens + (l - c.r)) / l : c.twoR;
    if (gIn + rise <= sMin) {
      return pi * rise * ((2.0 * l - gIn) - (gIn + rise)) / (4.0 * sMin); // all clipped
    }
    g1 = gIn;
    delta = rise;
    if (gIn < sMin) {
      const double dS = sMin - gIn;
      clipped = pi * dS * ((2.0 * l - gIn) - sMin) / (4.0 * sMin);
      g1 = sMin;
      delta = rise - dS;
    }
  }
  return clipped + 0.5 * pi * (l * gasLensLog1p(delta / g1) - delta);
}

/// Lens conductance κ_g I, W/K.
DEM_HD double gasLensConductance(const GasLensParams& p, double kG, double ri, double rj,
                                 double l) {
  return kG * gasLensIntegral(p, ri, rj, l).value;
}

/// Heat into particle i through the gas lens, W (Eq. 24). Antisymmetric bitwise.
DEM_HD double gasLensHeat(const GasLensParams& p, double kG, double ri, double rj, double l,
                          double ti, double tj) {
  return gasLensConductance(p, kG, ri, rj, l) * (tj - ti);
}

} // namespace coredem::dem::kernels
