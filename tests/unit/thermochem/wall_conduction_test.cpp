// Particle–wall conduction (kernels/wall_conduction.h): contact conductance against
// Batchelor–O'Brien with r_c = √(R² − h²), the closed-form lens integral against an independent
// long-double quadrature of its definition, and the wall as the limit of a very large sphere
// in the particle–particle kernels (docs/physics.md §3.2–3.3).
#include <cmath>

#include <gtest/gtest.h>

#include <coredem/dem/kernels/conduction_contact.h>
#include <coredem/dem/kernels/conduction_gas_lens.h>
#include <coredem/dem/kernels/wall_conduction.h>

namespace k = coredem::dem::kernels;

namespace {
constexpr double kPi = 3.141592653589793;
constexpr double kR = 5.0e-4; // 1 mm particle

// Independent reference: I = ∫_{R_in}^{R_out} 2π r dr / max(h − √(R² − r²), s_min), gap from
// the direct formula in long double, the clipped disc exact (root by bisection), the rest by
// 10-point Gauss–Legendre on panels graded geometrically towards the inner end (ratio 1.02).
long double fineWallLens(long double r, long double h, long double flpc, long double sMin) {
  const long double rl = (1 + flpc) * r;
  if (h >= rl)
    return 0;
  const long double rIn = h < r ? std::sqrt(r * r - h * h) : 0.0L;
  const long double rOut = std::min(r, std::sqrt(rl * rl - h * h));
  if (rOut <= rIn)
    return 0;
  auto gap = [&](long double s) { return h - std::sqrt(r * r - s * s); };
  long double lo = rIn;
  long double value = 0;
  if (gap(rIn) < sMin) {
    long double a = rIn, b = rOut;
    if (gap(rOut) < sMin) {
      a = rOut;
    } else {
      for (int it = 0; it < 200; ++it) {
        const long double m = 0.5L * (a + b);
        (gap(m) < sMin ? a : b) = m;
      }
    }
    value += kPi * (a * a - rIn * rIn) / sMin;
    lo = a;
  }
  if (rOut <= lo)
    return value;
  static const long double x[5] = {0.1488743389816312108848260L, 0.4333953941292471907992659L,
                                   0.6794095682990244062343274L, 0.8650633666889845107320967L,
                                   0.9739065285171717200779640L};
  static const long double w[5] = {0.2955242247147528701738930L, 0.2692667193099963550912269L,
                                   0.2190863625159820439955349L, 0.1494513491505805931457763L,
                                   0.0666713443086881375935688L};
  // Panels: widths growing by 1.02 from each end towards the middle (first width 1e-7 of the
  // interval): the integrand has a kink at lo and a square-root end point at R_out = R.
  auto panel = [&](long double a, long double b) {
    const long double c = 0.5L * (a + b), d = 0.5L * (b - a);
    long double sum = 0;
    for (int q = 0; q < 5; ++q) {
      for (int sgn = -1; sgn <= 1; sgn += 2) {
        const long double s = c + sgn * d * x[q];
        sum += w[q] * d * 2 * kPi * s / std::max(gap(s), sMin);
      }
    }
    return sum;
  };
  const long double mid = 0.5L * (lo + rOut);
  long double width = (rOut - lo) * 1e-7L;
  for (long double a = lo; a < mid; width *= 1.02L) {
    const long double b = std::min(mid, a + width);
    value += panel(a, b);
    a = b;
  }
  width = (rOut - lo) * 1e-7L;
  for (long double b = rOut; b > mid; width *= 1.02L) {
    const long double a = std::max(mid, b - width);
    value += panel(a, b);
    b = a;
  }
  return value;
}

k::WallConductionParams params(double flpc = 0.2, double sMin = 1e-6) {
  k::WallConductionParams p;
  p.lensFraction = flpc;
  p.minSeparation = sMin;
  return p;
}
} // namespace

TEST(WallConduction, ContactRadiusAndConductance) {
  const double delta = 1.0e-5, h = kR - delta;
  // r_c = √(R² − h²) for the (rounded) h, in long double.
  const long double hl = h, rl = kR;
  const double rc = static_cast<double>(std::sqrt(rl * rl - hl * hl));
  EXPECT_NEAR(k::wallContactRadius(kR, h), rc, 1e-15 * rc);
  // 4 kp kw/(kp + kw) r_c, glass (1 W/m/K) on steel (16 W/m/K).
  const double g = k::wallContactConductance(1.0, 16.0, kR, h);
  EXPECT_NEAR(g, 4.0 * 16.0 / 17.0 * rc, 2e-15 * g);
  EXPECT_EQ(k::wallContactConductance(1.0, 16.0, kR, kR), 0.0);        // touching: r_c = 0
  EXPECT_EQ(k::wallContactConductance(1.0, 16.0, kR, kR + 1e-9), 0.0); // apart
  EXPECT_EQ(k::wallContactConductance(0.0, 0.0, kR, h), 0.0);          // no conductivity
}

// The wall is the limit R_j → ∞ of the particle–particle kernel (Eqs. 22–23): with R_j = 1e6 R
// the contact radius differs by O(δ/R_j) relative.
TEST(WallConduction, ContactIsTheLargeSphereLimit) {
  for (double delta : {1e-7, 1e-6, 1e-5, 5e-5}) {
    const double h = kR - delta;
    const double big = 1e6 * kR;
    const double pair = k::contactConductance(1.0, 16.0, kR, big, big + h);
    const double wall = k::wallContactConductance(1.0, 16.0, kR, h);
    EXPECT_NEAR(pair, wall, 1e-6 * wall) << "delta = " << delta;
  }
}

TEST(WallConduction, LensClosedFormMatchesQuadrature) {
  struct Case {
    double h, flpc, sMin;
  };
  const Case cases[] = {
      {kR - 1e-5, 0.2, 1e-6},                          // in contact (R_in = r_c)
      {kR - 1e-7, 0.2, 1e-6},                          // slight contact
      {kR, 0.2, 1e-6},                                 // touching
      {kR + 5e-7, 0.2, 1e-6},                          // gap below s_min: clipped disc + annulus
      {kR + 1e-5, 0.2, 1e-6},                          // gap 10 µm: no clipping
      {kR + 5e-5, 0.2, 1e-6},  {1.15 * kR, 0.2, 1e-6}, // lens barely reaches the wall
      {kR + 2e-6, 0.5, 4e-10}, // wide lens (R_out = R), MFiX's commented s_min
      {kR - 2e-5, 0.2, 1e-4},  // large s_min: mostly clipped
      {5e-7, 0.2, 1e-6},       // centre within s_min of the wall: all clipped
  };
  for (const Case& c : cases) {
    const double got = k::wallLensIntegral(params(c.flpc, c.sMin), kR, c.h);
    const double want = static_cast<double>(fineWallLens(kR, c.h, c.flpc, c.sMin));
    ASSERT_GT(want, 0.0);
    // 1e-9: the reference quadrature's accuracy (panels graded towards the inner end).
    EXPECT_NEAR(got, want, 1e-9 * want) << "h = " << c.h << " flpc = " << c.flpc;
  }
  EXPECT_EQ(k::wallLensIntegral(params(), kR, 1.2 * kR), 0.0); // lens ends at the wall
  EXPECT_EQ(k::wallLensIntegral(params(), kR, 2.0 * kR), 0.0);
}

// The lens integral is continuous where contact starts (h = R) and vanishes where the lens
// leaves the wall (h → R_lens).
TEST(WallConduction, LensContinuity) {
  const auto p = params();
  const double at = k::wallLensIntegral(p, kR, kR);
  EXPECT_NEAR(k::wallLensIntegral(p, kR, kR * (1 - 1e-12)), at, 1e-9 * at);
  EXPECT_NEAR(k::wallLensIntegral(p, kR, kR * (1 + 1e-12)), at, 1e-9 * at);
  const double edge = k::wallLensIntegral(p, kR, 1.2 * kR * (1 - 1e-10));
  EXPECT_LT(edge, 1e-9 * at);
  EXPECT_GE(edge, 0.0);
}

// Limit of the particle–particle lens (Eqs. 24–26) with a very large partner: its lens
// ((1+FLPC)·R_big) covers the particle's whole facing hemisphere, i.e. the wall lens with
// R_out = R (here FLPC = 0.5 ≥ √2 − 1 near contact). The partner's curvature adds r²/(2 R_big)
// to the wall gap h − √(R² − r²) ≥ r²/(2R) (h ≥ R) or to the clipped-free part in contact:
// at most R/R_big = 1e-4 relative to the integrand at R_big = 1e4 R, so they agree to 1e-4.
TEST(WallConduction, LensIsTheLargeSphereLimit) {
  k::GasLensParams lp;
  lp.lensFraction = 0.2;
  lp.minSeparation = 1e-6;
  lp.relTol = 1e-10;
  const double big = 1e4 * kR;
  for (double h : {kR - 1e-5, kR, kR + 3e-6, kR + 2e-5}) {
    const double pair = k::gasLensIntegral(lp, kR, big, big + h).value;
    const double wall = k::wallLensIntegral(params(0.5, 1e-6), kR, h);
    EXPECT_NEAR(pair, wall, 1e-4 * wall) << "h = " << h;
    EXPECT_LT(pair, wall); // the curved partner is farther away everywhere
  }
}

TEST(WallConduction, HeatSignAndSwitches) {
  auto p = params();
  const double h = kR - 1e-5;
  const double gC = k::wallContactConductance(1.0, 1.0, kR, h);
  const double gL = 0.0257 * k::wallLensIntegral(p, kR, h);
  EXPECT_NEAR(k::wallConductance(p, 1.0, 1.0, 0.0257, kR, h), gC + gL, 1e-15 * (gC + gL));
  // Hot wall heats the particle.
  EXPECT_GT(k::wallConductionHeat(p, 1.0, 1.0, 0.0257, kR, h, 363.15, 293.15), 0.0);
  EXPECT_NEAR(k::wallConductionHeat(p, 1.0, 1.0, 0.0257, kR, h, 363.15, 293.15), (gC + gL) * 70.0,
              1e-12 * (gC + gL) * 70.0);
  p.lens = false;
  EXPECT_EQ(k::wallConductance(p, 1.0, 1.0, 0.0257, kR, h), gC);
  EXPECT_EQ(k::wallConductance(params(), 1.0, 1.0, 0.0, kR, h), gC); // no gas: contact only
  p.contact = false;
  EXPECT_EQ(k::wallConductance(p, 1.0, 1.0, 0.0257, kR, h), 0.0);
}
