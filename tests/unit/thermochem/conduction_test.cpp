// Contact conduction (docs/physics.md §3.2) and gas-lens conduction (§3.3) vs the MFiX reference
// constants (§8.1, §8.2), reference values computed independently with mpmath (50 digits) by
// reference/make_thermochem_reference.py (thermochem_reference.h), closed forms and an
// independent fine long-double quadrature.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <coredem/dem/kernels/conduction_contact.h>
#include <coredem/dem/kernels/conduction_gas_lens.h>
#include <coredem/dem/kernels/conduction_quadrature.h>
#include <coredem/dem/verification/analytic.h>

#include "reference/thermochem_reference.h"

namespace k = coredem::dem::kernels;
namespace v = coredem::dem::verification;
namespace ref = coredem::test::thermochem_ref;

namespace {
constexpr double kPi = 3.141592653589793;
const double kMfixCcDistance = (0.4799731 - 0.1499864) * 1e-2; // §8.1 positions
const double kMfixPfpDistance = (1.498 - 1.150) * 1e-2;        // §8.2 positions

// Independent reference for the lens integral: direct gap formula in long double (64-bit
// mantissa), root of gap = s_min by bisection, the clipped part integrated exactly, the rest by
// 10-point Gauss–Legendre on panels graded geometrically towards both ends (ratio 1.02).
long double fineLensIntegral(long double r1, long double r2, long double l, long double flpc,
                             long double sMin) {
  const long double big = std::max(r1, r2);
  const long double small = std::min(r1, r2);
  const long double rLens = (1 + flpc) * big;
  auto chord = [](long double ra, long double rb, long double d) {
    const long double x = (ra * ra - rb * rb + d * d) / (2 * d);
    return std::sqrt(ra * ra - x * x);
  };
  // R_out: Eq. 26, or R_S once the lens covers the small sphere's facing hemisphere ([C]).
  const long double rOut = l * l <= rLens * rLens - small * small ? small : chord(rLens, small, l);
  const long double rIn = l < big + small ? chord(big, small, l) : 0.0L;
  auto gap = [&](long double r) {
    return l - std::sqrt(big * big - r * r) - std::sqrt(small * small - r * r);
  };
  long double lo = rIn;
  long double hi = rOut;
  if (gap(rIn) < sMin) {
    for (int i = 0; i < 200; ++i) {
      const long double mid = 0.5L * (lo + hi);
      (gap(mid) < sMin ? lo : hi) = mid;
    }
  } else {
    hi = rIn;
  }
  const long double rStar = hi;
  long double total = kPi * (rStar * rStar - rIn * rIn) / sMin;
  // 10-point Gauss–Legendre nodes/weights (positive half; numpy.polynomial.legendre.leggauss).
  static const long double x[5] = {0.14887433898163122L, 0.4333953941292472L, 0.6794095682990244L,
                                   0.8650633666889845L, 0.9739065285171717L};
  static const long double w[5] = {0.295524224714753L, 0.2692667193099965L, 0.219086362515982L,
                                   0.14945134915058036L, 0.06667134430868807L};
  auto panel = [&](long double a, long double b) {
    const long double c = 0.5L * (a + b);
    const long double h = 0.5L * (b - a);
    long double s = 0;
    for (int i = 0; i < 5; ++i) {
      for (long double r : {c - h * x[i], c + h * x[i]}) {
        s += w[i] * 2 * kPi * r / std::max(gap(r), sMin);
      }
    }
    return s * h;
  };
  // Panels graded geometrically (ratio 1.02) towards R_in from the first half of [r*, R_out]
  // and towards R_out in the second half (when R_out = R_S the gap has a square-root branch
  // point there).
  const long double mid = 0.5L * (rStar + rOut);
  long double a = rStar;
  long double width = std::max((rStar - rIn) * 0.02L, (rOut - rIn) * 1e-12L);
  while (a < mid) {
    const long double b = std::min(mid, a + width);
    total += panel(a, b);
    a = b;
    width = std::max(width, (a - rIn) * 0.02L);
  }
  long double b = rOut;
  width = (rOut - mid) * 1e-12L;
  while (b > mid) {
    const long double a2 = std::max(mid, b - width);
    total += panel(a2, b);
    b = a2;
    width = std::max(width, (rOut - b) * 0.02L);
  }
  return total;
}

// Equal spheres: I has a closed form. With w = √(R² − r²):
//   ∫ 2π r dr / (l − 2w) = 2π [F(w_a) − F(w_b)],  F(w) = −w/2 − (l/4) ln(l − 2w).
long double equalSpheresLensIntegral(long double rad, long double l, long double flpc,
                                     long double sMin) {
  const long double rLens = (1 + flpc) * rad;
  const long double x = (rLens * rLens - rad * rad + l * l) / (2 * l);
  const long double rOut = std::sqrt(rLens * rLens - x * x);
  const long double rIn = l < 2 * rad ? std::sqrt(rad * rad - l * l / 4) : 0.0L;
  auto F = [&](long double w) { return -w / 2 - l / 4 * std::log(l - 2 * w); };
  const long double wOut = std::sqrt(rad * rad - rOut * rOut);
  if (l - 2 * std::sqrt(rad * rad - rIn * rIn) >= sMin) { // never clipped
    return 2 * kPi * (F(std::sqrt(rad * rad - rIn * rIn)) - F(wOut));
  }
  const long double wStar = (l - sMin) / 2; // gap = s_min
  const long double rStar = std::sqrt(rad * rad - wStar * wStar);
  return kPi * (rStar * rStar - rIn * rIn) / sMin + 2 * kPi * (F(wStar) - F(wOut));
}
} // namespace

// ---- quadrature --------------------------------------------------------------------------

// K15 is exact for polynomials of degree ≤ 22 on one panel; the adaptive driver reaches the
// requested tolerance on a peaked function (∫ dx/(x² + 1e-6) on [−1, 1] = 2000 atan(1000)).
TEST(Quadrature, GaussKronrodExactnessAndAdaptivity) {
  for (int deg = 0; deg <= 22; ++deg) {
    double err = 0.0;
    const double val =
        k::gaussKronrod15([deg](double x) { return std::pow(x, deg); }, 0.0, 2.0, err);
    const double exact = std::pow(2.0, deg + 1) / (deg + 1);
    EXPECT_NEAR(val, exact, 1e-14 * exact) << "degree " << deg;
  }
  const auto r =
      k::integrateAdaptive([](double x) { return 1.0 / (x * x + 1e-6); }, -1.0, 1.0, 1e-12);
  const double exact = 2000.0 * std::atan(1000.0);
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(r.value, exact, 1e-12 * exact);
}

// ---- contact conduction -------------------------------------------------------------------

// MFiX-CC (§8.1): r_c, a = A_C and b vs the reference script (exact decimal positions). The
// overlap 1.33e-8 m is a difference of ~3.3e-3 m distances: the double distance carries ~3e-11
// relative error into it, half of that into r_c → 1e-10 relative.
TEST(ContactConduction, MfixReferenceConstants) {
  const double rc = k::intersectionCircleRadius(1.5e-3, 1.8e-3, kMfixCcDistance);
  EXPECT_NEAR(rc, ref::kMfixCcContactRadius, 1e-10 * rc);
  const auto c = v::contactConductionCoefficients(3.0e-3, v::musserMaterialA(), 3.6e-3,
                                                  v::musserMaterialB(), kMfixCcDistance);
  EXPECT_NEAR(c.a, ref::kMfixCcA, 1e-10 * c.a);
  EXPECT_NEAR(c.b, ref::kMfixCcB, 1e-10 * c.b);
  // The MFiX file's A_C = 0.01027998273952850 s⁻¹ (15 digits) agrees to its rounding.
  EXPECT_NEAR(c.a, 0.01027998273952850, 1e-10 * c.a);
  // Errata check: the seed's factor 2 would give half of A_C.
  EXPECT_GT(std::fabs(c.a / ref::kMfixCcA - 0.5), 0.4);
}

// Stable intersection radius: equal spheres have r_c = √((R − l/2)(R + l/2)) exactly; the
// Heron form must hold 1e-14 relative down to overlaps of 1e-12 R where the textbook formula
// loses most digits.
TEST(ContactConduction, IntersectionRadiusIsAccurateForTinyOverlaps) {
  const double rad = 1.5e-3;
  for (double ov : {1e-5, 1e-9, 1e-12, 1e-14}) {
    const double l = 2.0 * rad - ov * rad;
    const double exact = std::sqrt((rad - 0.5 * l) * (rad + 0.5 * l));
    EXPECT_NEAR(k::intersectionCircleRadius(rad, rad, l), exact, 1e-14 * exact) << ov;
  }
  EXPECT_EQ(k::intersectionCircleRadius(1e-3, 2e-3, 3e-3), 0.0);    // touching: no circle
  EXPECT_EQ(k::intersectionCircleRadius(1e-3, 2e-3, 3.1e-3), 0.0);  // apart
  EXPECT_EQ(k::intersectionCircleRadius(1e-3, 2e-3, 0.5e-3), 1e-3); // inside [C]
  EXPECT_EQ(k::contactConductance(1.0, 2.0, 1e-3, 2e-3, 3e-3), 0.0);
}

// Seed variants (§8.1 table, the reference script's full digits): particle 1 = A (3.0 mm,
// 373.15 K), particle 2 = material B (278.15 K). The overlaps are ≥ 3e-3 of the distance, so
// the double distance costs ≤ 1e-13 relative in r_c: r_c, a, b at 1e-12 relative, the
// temperatures at 1e-9 K.
TEST(ContactConduction, SeedVariantTable) {
  for (const auto& r : ref::kSeedContact) {
    SCOPED_TRACE(r.d2);
    SCOPED_TRACE(r.ov);
    const double l = 1.5e-3 + 0.5 * r.d2 - r.ov;
    EXPECT_NEAR(k::intersectionCircleRadius(1.5e-3, 0.5 * r.d2, l), r.rc, 1e-12 * r.rc);
    const auto c = v::contactConductionCoefficients(3.0e-3, v::musserMaterialA(), r.d2,
                                                    v::musserMaterialB(), l);
    EXPECT_NEAR(c.a, r.a, 1e-12 * r.a);
    EXPECT_NEAR(c.b, r.b, 1e-12 * r.b);
    EXPECT_NEAR(v::twoParticleEquilibrium(c.a, c.b, 373.15, 278.15), r.tInf, 1e-9);
    const auto t = v::twoParticleExchange(c.a, c.b, 373.15, 278.15, 10.0);
    EXPECT_NEAR(t.t1, r.t1, 1e-9);
    EXPECT_NEAR(t.t2, r.t2, 1e-9);
  }
}

// Q_ij = −Q_ji bitwise, whichever particle evaluates the pair, for both conduction kernels.
TEST(Conduction, PairTermsAreExactlyAntisymmetric) {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> rad(0.2e-3, 2e-3), k(0.05, 60.0), t(250.0, 1300.0),
      frac(0.9, 1.15);
  k::GasLensParams lens;
  for (int n = 0; n < 400; ++n) {
    const double ri = rad(rng), rj = rad(rng), ki = k(rng), kj = k(rng), ti = t(rng), tj = t(rng);
    const double l = frac(rng) * (ri + rj);
    const double qij = k::contactConductionHeat(ki, kj, ri, rj, l, ti, tj);
    const double qji = k::contactConductionHeat(kj, ki, rj, ri, l, tj, ti);
    EXPECT_EQ(qij, -qji);
    const double pij = k::gasLensHeat(lens, 0.05, ri, rj, l, ti, tj);
    const double pji = k::gasLensHeat(lens, 0.05, rj, ri, l, tj, ti);
    EXPECT_EQ(pij, -pji);
    if (l < ri + rj) {
      EXPECT_NE(qij, 0.0);
    }
  }
}

// ---- gas lens ------------------------------------------------------------------------------

// MFiX-PFP (§8.2): R_out, R_in = 0, I and a, b vs the reference script (mpmath quadrature at
// 50 digits); the closed form is within kGasLensClosedFormRelError = 1e-13 of I, the double
// distance adds ~1e-16: 1e-12 relative. MFiX's own a = 0.0401067383 comes from its loose
// EPS = 1e-2 Simpson (6.7e-5 relative).
TEST(GasLens, MfixReferenceConstants) {
  const k::GasLensParams p;
  const auto geo = k::gasLensGeometry(p, 1.5e-3, 1.8e-3, kMfixPfpDistance);
  EXPECT_TRUE(geo.active);
  EXPECT_FALSE(geo.contact);
  EXPECT_EQ(geo.rIn, 0.0);
  EXPECT_NEAR(geo.rOut, ref::kMfixPfpOuterRadius, 1e-12 * ref::kMfixPfpOuterRadius);
  const auto in = k::gasLensIntegral(p, 1.5e-3, 1.8e-3, kMfixPfpDistance);
  EXPECT_TRUE(in.converged);
  EXPECT_NEAR(in.value, ref::kMfixPfpIntegral, 1e-12 * in.value);
  const auto c = v::gasLensCoefficients(3.0e-3, v::musserMaterialA(), 3.6e-3, v::musserMaterialB(),
                                        kMfixPfpDistance, v::kMusserLensGasConductivity);
  EXPECT_NEAR(c.a, ref::kMfixPfpA, 1e-12 * c.a);
  EXPECT_NEAR(c.b, ref::kMfixPfpB, 1e-12 * c.b);
  // The MFiX file's loose constants.
  EXPECT_NEAR(c.a, 0.0401067383, 1e-4 * c.a);
  EXPECT_NEAR(c.b, 0.0160219735, 1e-4 * c.b);
}

// Seed gap / overlap variants (§8.2 table, the reference script's full digits): I, a and b at
// 1e-12 relative (as above).
TEST(GasLens, SeedVariantsMatchReferenceScript) {
  for (const auto& r : ref::kSeedLens) {
    SCOPED_TRACE(r.gap);
    SCOPED_TRACE(r.sMin);
    k::GasLensParams p;
    p.minSeparation = r.sMin;
    const double l = 1.5e-3 + 1.8e-3 + r.gap;
    const auto in = k::gasLensIntegral(p, 1.5e-3, 1.8e-3, l);
    EXPECT_TRUE(in.converged);
    EXPECT_NEAR(in.value, r.integral, 1e-12 * r.integral);
    const auto c =
        v::gasLensCoefficients(3.0e-3, v::musserMaterialA(), 3.6e-3, v::musserMaterialB(), l,
                               v::kMusserLensGasConductivity, p);
    EXPECT_NEAR(c.a, r.a, 1e-12 * r.a);
    EXPECT_NEAR(c.b, r.b, 1e-12 * r.b);
  }
}

// Accuracy target 1e-8 relative (docs/physics.md §3.3): compare against the closed form for equal
// spheres and the independent long-double quadrature for unequal spheres, in and out of
// contact, with s_min from 4e-10 to 1e-6 m. Observed agreement is ~1e-13; assert 1e-10 for
// the closed form gasLensIntegral() and the adaptive gasLensIntegralReference() alike.
TEST(GasLens, QuadratureAccurateToBetterThan1e8) {
  for (double sMin : {4e-10, 1e-8, 1e-6}) {
    for (double gap : {-4e-5, -1e-6, -1e-9, 1e-9, 1e-7, 1e-5, 2e-4}) {
      SCOPED_TRACE(sMin);
      SCOPED_TRACE(gap);
      k::GasLensParams p;
      p.minSeparation = sMin;
      const double rad = 1.5e-3;
      const double le = 2 * rad + gap;
      const auto eq = k::gasLensIntegral(p, rad, rad, le);
      const long double exactEq = equalSpheresLensIntegral(rad, le, 0.2L, sMin);
      EXPECT_TRUE(eq.converged);
      EXPECT_NEAR(eq.value, static_cast<double>(exactEq), 1e-10 * eq.value);
      const double lu = 1.5e-3 + 1.8e-3 + gap;
      const auto un = k::gasLensIntegral(p, 1.5e-3, 1.8e-3, lu);
      const long double fine = fineLensIntegral(1.5e-3L, 1.8e-3L, lu, 0.2L, sMin);
      EXPECT_TRUE(un.converged);
      EXPECT_NEAR(un.value, static_cast<double>(fine), 1e-10 * un.value);
      // The adaptive reference the closed form is swept against meets the same bound.
      EXPECT_NEAR(k::gasLensIntegralReference(p, rad, rad, le).value, static_cast<double>(exactEq),
                  1e-10 * eq.value);
      EXPECT_NEAR(k::gasLensIntegralReference(p, 1.5e-3, 1.8e-3, lu).value,
                  static_cast<double>(fine), 1e-10 * un.value);
    }
  }
}

// Very polydisperse pairs (R_S/R_L = 0.1, 0.2), where R_out = R_S and the gap has a
// square-root branch point at the outer limit, in and out of contact: 1e-10 as well.
TEST(GasLens, QuadratureAccurateForSmallSizeRatios) {
  for (double ratio : {0.1, 0.2}) {
    for (double rel : {-0.05, -1e-6, 1e-6, 1e-2, 0.05}) {
      for (double sMin : {4e-10, 1e-6}) {
        SCOPED_TRACE(ratio);
        SCOPED_TRACE(rel);
        SCOPED_TRACE(sMin);
        k::GasLensParams p;
        p.minSeparation = sMin;
        const double big = 1e-3;
        const double small = ratio * big;
        const double l = (big + small) * (1.0 + rel);
        const auto in = k::gasLensIntegral(p, big, small, l);
        const long double fine = fineLensIntegral(big, small, l, 0.2L, sMin);
        EXPECT_TRUE(in.converged);
        EXPECT_GT(in.value, 0.0);
        EXPECT_NEAR(in.value, static_cast<double>(fine), 1e-10 * in.value);
        EXPECT_NEAR(k::gasLensIntegralReference(p, big, small, l).value, static_cast<double>(fine),
                    1e-10 * in.value);
      }
    }
  }
}

// R_out is continuous in l where it switches from Eq. 26 to R_S ([C], l² = R_lens² − R_S²).
TEST(GasLens, OuterRadiusContinuousAtHemisphereSwitch) {
  const k::GasLensParams p;
  const double big = 1e-3;
  const double small = 0.1e-3;
  const double rLens = 1.2 * big;
  const double lSwitch = std::sqrt(rLens * rLens - small * small);
  const auto below = k::gasLensGeometry(p, big, small, lSwitch * (1.0 - 1e-12));
  const auto above = k::gasLensGeometry(p, big, small, lSwitch * (1.0 + 1e-12));
  EXPECT_EQ(below.rOut, small);
  EXPECT_NEAR(above.rOut, small, 1e-5 * small); // chord radius → R_S as √(Δl)
  EXPECT_LE(above.rOut, small);
  // Beyond the switch: Eq. 26.
  const double l = 1.01 * lSwitch;
  const double x = (rLens * rLens - small * small + l * l) / (2.0 * l);
  const double eq26 = std::sqrt(rLens * rLens - x * x);
  EXPECT_NEAR(k::gasLensGeometry(p, big, small, l).rOut, eq26, 1e-12 * eq26);
}

// Closed form when the whole lens is clipped (s_min ≥ max gap): I = π(R_out² − R_in²)/s_min.
// And no lens beyond reach: l ≥ R_lens + R_S → 0.
TEST(GasLens, ClippedLimitAndReach) {
  k::GasLensParams p;
  p.minSeparation = 1.0; // 1 m ≫ any gap
  for (double l : {3.2e-3, 3.3e-3, 3.4e-3}) {
    const auto geo = k::gasLensGeometry(p, 1.5e-3, 1.8e-3, l);
    const double exact = kPi * (geo.rOut * geo.rOut - geo.rIn * geo.rIn) / p.minSeparation;
    EXPECT_NEAR(k::gasLensIntegral(p, 1.5e-3, 1.8e-3, l).value, exact, 1e-14 * exact) << l;
  }
  k::GasLensParams d;
  const double reach = 1.2 * 1.8e-3 + 1.5e-3;
  EXPECT_EQ(k::gasLensIntegral(d, 1.5e-3, 1.8e-3, reach).value, 0.0);
  EXPECT_GT(k::gasLensIntegral(d, 1.5e-3, 1.8e-3, reach * (1 - 1e-6)).value, 0.0);
  // s_min ≤ 0 would make the contact integral diverge: reported as not converged.
  k::GasLensParams bad;
  bad.minSeparation = 0.0;
  EXPECT_FALSE(k::gasLensIntegral(bad, 1.5e-3, 1.8e-3, 3.2e-3).converged);
  // Lens around the larger sphere: swapping the argument order changes nothing.
  EXPECT_EQ(k::gasLensIntegral(d, 1.8e-3, 1.5e-3, 3.4e-3).value,
            k::gasLensIntegral(d, 1.5e-3, 1.8e-3, 3.4e-3).value);
}

// ---- closed form vs reference quadrature and 40-digit values ------------------------------

// The closed form gasLensIntegral() against 40-digit values (mpmath quadrature of Eq. 24 at the
// same binary inputs, R_lens = (1.0 + 0.2)·R_L rounded as in the kernel; kLensIntegral of
// reference/make_thermochem_reference.py): equal and unequal radii, R_S/R_L from 0.1 to 1, R from
// 1e-4 to 1e-2 m, overlaps to 5 % of R_S, gaps up to the lens reach (the last three rows 1e-6
// below it, where the adaptive reference loses digits), s_min from 1e-10 to 1e-5 m. Observed
// ≤ 1.3e-15; asserted at the stated bound kGasLensClosedFormRelError = 1e-13.
TEST(GasLens, ClosedFormMatchesFortyDigitValues) {
  for (const auto& r : ref::kLensIntegral) {
    SCOPED_TRACE(::testing::Message()
                 << "R_L " << r.big << " R_S " << r.small << " l " << r.l << " s_min " << r.sMin);
    k::GasLensParams p;
    p.minSeparation = r.sMin;
    const auto in = k::gasLensIntegral(p, r.big, r.small, r.l);
    EXPECT_TRUE(in.converged);
    EXPECT_NEAR(in.value, r.integral, k::kGasLensClosedFormRelError * r.integral);
    EXPECT_LE(in.error, k::kGasLensClosedFormRelError * in.value);
  }
}

// Dense sweep over the DEM range against the adaptive reference (gasLensIntegralReference at
// relTol 1e-12): R_L = 1e-4, 1e-3, 1e-2 m; R_S/R_L = 0.1 … 1 (15 ratios, including the
// hemisphere switch near 0.19); s_min = 1e-10 … 1e-5 m; surface gaps from −5 % of R_S
// (log-spaced down to 1e-9 of it, both signs) to 1e-6 below the lens reach (and two beyond it,
// where both give 0; the closed form's limits follow gasLensGeometry()). Asserted 1e-12
// relative (5e-14 observed; the reference runs at relTol 1e-12), and 5e-9 at the last point
// before the reach: the reference is the limit there (its u = ln(g0 + c0 r²) substitution
// cancels in e^u − g0 when c0 r² ≪ g0; 1.3e-9 observed), while the closed form stays within
// 1e-15 of 40-digit values at those points (test above). Also: both orders of the radii give
// bitwise the same value.
TEST(GasLens, ClosedFormMatchesAdaptiveReferenceOverDemRange) {
  const double ratios[] = {0.1, 0.15, 0.18, 0.19, 0.2, 0.25, 0.3, 0.4,
                           0.5, 0.6,  0.7,  0.8,  0.9, 0.99, 1.0};
  double worst = 0.0;
  double worstAtReach = 0.0;
  int count = 0;
  for (double big : {1e-4, 1e-3, 1e-2}) {
    for (double ratio : ratios) {
      for (double sMin : {1e-10, 1e-9, 1e-8, 1e-7, 1e-6, 1e-5}) {
        const double small = ratio * big;
        const double reachGap = 0.2 * big; // l = R_lens + R_S
        std::vector<double> gaps;
        for (int e = 0; e <= 9; ++e) {
          gaps.push_back(-0.05 * small * std::pow(10.0, -e));
          gaps.push_back(0.05 * small * std::pow(10.0, -e));
        }
        for (int m = 1; m <= 20; ++m)
          gaps.push_back(reachGap * (m / 20.0) * (1.0 - 1e-6));
        gaps.push_back(reachGap * (1.0 + 1e-9)); // beyond the reach: no lens
        gaps.push_back(reachGap * 1.5);
        for (double gap : gaps) {
          const bool atReach = gap > reachGap * (1.0 - 2e-6);
          const double l = big + small + gap;
          k::GasLensParams p;
          p.minSeparation = sMin;
          p.relTol = 1e-12;
          const auto closed = k::gasLensIntegral(p, big, small, l);
          const auto ref = k::gasLensIntegralReference(p, big, small, l);
          SCOPED_TRACE(::testing::Message()
                       << "R_L " << big << " R_S " << small << " gap " << gap << " s_min " << sMin);
          ASSERT_TRUE(ref.converged);
          EXPECT_TRUE(closed.converged);
          EXPECT_EQ(closed.value, k::gasLensIntegral(p, small, big, l).value);
          EXPECT_EQ(closed.value > 0.0, k::gasLensGeometry(p, big, small, l).active);
          if (ref.value == 0.0) {
            EXPECT_EQ(closed.value, 0.0);
            continue;
          }
          const double rel = std::fabs(closed.value - ref.value) / ref.value;
          EXPECT_LE(rel, atReach ? 5e-9 : 1e-12);
          (atReach ? worstAtReach : worst) = std::max(atReach ? worstAtReach : worst, rel);
          ++count;
        }
      }
    }
  }
  EXPECT_GT(count, 10000);
  std::printf("gas lens: %d pairs, closed form vs adaptive reference: worst %.2e relative "
              "(%.2e at the reach)\n",
              count, worst, worstAtReach);
}

// s_min dominates touching particles (§3.3): 1e-6 → 4e-10 m roughly doubles I (0.0351 → 0.0752,
// the seed lens rows of the reference script at 1e-5 m overlap).
TEST(GasLens, MinimumSeparationControlsTouchingCase) {
  k::GasLensParams coarse;
  k::GasLensParams fine;
  fine.minSeparation = 4e-10;
  const double l = 3.3e-3 - 1e-5;
  const auto& r6 = ref::kSeedLens[3];
  const auto& r10 = ref::kSeedLens[4];
  ASSERT_EQ(r6.gap, -1e-5);
  ASSERT_EQ(r6.sMin, 1e-6);
  ASSERT_EQ(r10.gap, -1e-5);
  ASSERT_EQ(r10.sMin, 4e-10);
  const double i6 = k::gasLensIntegral(coarse, 1.5e-3, 1.8e-3, l).value;
  const double i10 = k::gasLensIntegral(fine, 1.5e-3, 1.8e-3, l).value;
  EXPECT_NEAR(i6, r6.integral, 1e-12 * i6);
  EXPECT_NEAR(i10, r10.integral, 1e-12 * i10);
  EXPECT_GT(i10 / i6, 2.0);
}
