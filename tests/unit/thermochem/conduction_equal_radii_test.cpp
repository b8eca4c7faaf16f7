// The equal-radii conduction kernels of the heat pair pass (heat.h),
// intersectionCircleRadiusEqual() and gasLensIntegralEqualRadii(), against exact values and the
// general kernels over the whole range of centre distances the pair pass feeds them, and the lens
// logarithm gasLensLog1p().
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <coredem/dem/kernels/conduction_contact.h>
#include <coredem/dem/kernels/conduction_gas_lens.h>

#include "reference/thermochem_reference.h"

namespace k = coredem::dem::kernels;

namespace {

// Centre distances for spheres of radius r and lens fraction flpc: deep and shallow overlaps
// (relative 1e-12 … 0.5), touching, the clipped band, open gaps up to the lens reach and beyond,
// plus random ones.
std::vector<double> distances(double r, double flpc, double sMin) {
  std::vector<double> ls;
  const double reach = (1.0 + flpc) * r + r;
  for (int e = 0; e <= 12; ++e) {
    const double f = std::pow(10.0, -e);
    ls.push_back(2.0 * r * (1.0 - 0.5 * f)); // overlaps of R … 1e-12 R
    ls.push_back(2.0 * r * (1.0 - f * 1e-1));
    ls.push_back(2.0 * r + f * 1e-3 * r); // apart by 1e-3 R … 1e-15 R
  }
  ls.push_back(2.0 * r);
  ls.push_back(std::nextafter(2.0 * r, 0.0));
  ls.push_back(std::nextafter(2.0 * r, 1.0));
  ls.push_back(r);
  ls.push_back(std::nextafter(r, 1.0));
  for (double m : {0.25, 0.5, 0.9, 1.0, 1.1, 2.0, 10.0}) // around the clipping band
    ls.push_back(2.0 * r + m * sMin);
  for (int m = 1; m <= 40; ++m)
    ls.push_back(2.0 * r + (reach - 2.0 * r) * m / 40.0);
  ls.push_back(std::nextafter(reach, 0.0));
  ls.push_back(reach);
  ls.push_back(1.5 * reach);
  std::mt19937_64 rng(20261202);
  std::uniform_real_distribution<double> u(0.3 * r, 1.1 * reach);
  for (int m = 0; m < 2000; ++m)
    ls.push_back(u(rng));
  return ls;
}

} // namespace

// √((R − l/2)(R + l/2)) against the exact radius (long double) and the Heron form.
TEST(ContactConduction, EqualRadiiCircleWithinOneUlp) {
  int count = 0;
  double worst = 0.0;
  for (double r : {1e-4, 5e-4, 7.3e-4, 1e-3, 1e-2}) {
    for (double l : distances(r, 0.2, 1e-6)) {
      if (!(l >= r && l < 2.0 * r))
        continue; // the kernel's range (the pair pass takes the general one elsewhere)
      SCOPED_TRACE(::testing::Message() << "R " << r << " l " << l);
      const long double rl = r, ll = l;
      const long double exact = sqrtl((rl - 0.5L * ll) * (rl + 0.5L * ll));
      const double fast = k::intersectionCircleRadiusEqual(r, l);
      const double rel = static_cast<double>(fabsl(fast - exact) / exact);
      EXPECT_LE(rel, std::ldexp(1.0, -52));
      EXPECT_NEAR(fast, k::intersectionCircleRadius(r, r, l), 1e-15 * fast);
      worst = std::max(worst, rel);
      ++count;
    }
  }
  EXPECT_GT(count, 2000);
  std::printf("equal-radii contact circle: %d distances, worst %.2e relative\n", count, worst);
}

// The equal-radii lens form against the general closed form (kGasLensEqualRadiiRelDiff) over
// radii, lens fractions, s_min and centre distances from half-overlapping to beyond the reach
// (both 0 there), and at FLPC 0.2 against the adaptive reference at 1e-12 (5e-9 in the last
// 2e-6 of the lens gap, where the reference loses digits: conduction_test.cpp).
TEST(GasLens, EqualRadiiKernelMatchesTheGeneralOne) {
  int count = 0, positive = 0;
  double worst = 0.0, worstRef = 0.0;
  for (double r : {1e-4, 5e-4, 7.3e-4, 1e-3, 1e-2}) {
    for (double flpc : {0.0, 0.1, 0.2, 0.5, 1.0, 1.5}) {
      for (double sMin : {1e-10, 1e-8, 1e-6, 1e-5}) {
        k::GasLensParams p;
        p.lensFraction = flpc;
        p.minSeparation = sMin;
        p.relTol = 1e-12;
        const k::GasLensEqualRadii c = k::gasLensEqualRadii(p, r);
        const double reach = (1.0 + flpc) * r + r;
        int m = 0;
        for (double l : distances(r, flpc, sMin)) {
          SCOPED_TRACE(::testing::Message()
                       << "R " << r << " FLPC " << flpc << " s_min " << sMin << " l " << l);
          const double general = k::gasLensIntegral(p, r, r, l).value;
          const double equal = k::gasLensIntegralEqualRadii(p, c, l);
          ++count;
          if (general == 0.0) {
            EXPECT_EQ(equal, 0.0);
            continue;
          }
          ++positive;
          const double rel = std::fabs(equal - general) / general;
          EXPECT_LE(rel, k::kGasLensEqualRadiiRelDiff);
          worst = std::max(worst, rel);
          // Every tenth distance (the reference is slow), up to 1e-6 of the lens gap below
          // the reach, at the default FLPC: the range where conduction_test.cpp checks the
          // general form against the reference (which loses digits closer to the reach).
          const double reachGap = reach - 2.0 * r;
          if (flpc == 0.2 && m++ % 10 == 0 && l > r && l - 2.0 * r <= reachGap * (1.0 - 1e-6)) {
            const bool atReach = l - 2.0 * r > reachGap * (1.0 - 2e-6);
            const double ref = k::gasLensIntegralReference(p, r, r, l).value;
            const double relRef = std::fabs(equal - ref) / ref;
            EXPECT_LE(relRef, atReach ? 5e-9 : 1e-12);
            if (!atReach)
              worstRef = std::max(worstRef, relRef);
          }
        }
      }
    }
  }
  EXPECT_GT(positive, count / 2);
  std::printf("equal-radii gas lens: %d distances, worst %.2e relative to the general closed "
              "form, %.2e to the adaptive reference\n",
              count, worst, worstRef);
  // Invalid parameters: no lens, as the general function.
  k::GasLensParams bad;
  bad.minSeparation = 0.0;
  EXPECT_EQ(k::gasLensIntegralEqualRadii(bad, k::gasLensEqualRadii(bad, 1e-3), 1.9e-3), 0.0);
}

// The equal-radii rows of the 40-digit table (reference/make_thermochem_reference.py,
// conduction_test.cpp), same bound as the general closed form.
TEST(GasLens, EqualRadiiKernelMatchesFortyDigitValues) {
  int rows = 0;
  for (const auto& row : coredem::test::thermochem_ref::kLensIntegral) {
    if (row.big != row.small) {
      continue;
    }
    ++rows;
    const double r = row.big;
    SCOPED_TRACE(::testing::Message() << "R " << r << " l " << row.l << " s_min " << row.sMin);
    k::GasLensParams p;
    p.minSeparation = row.sMin;
    EXPECT_NEAR(k::gasLensIntegralEqualRadii(p, k::gasLensEqualRadii(p, r), row.l), row.integral,
                k::kGasLensClosedFormRelError * row.integral);
  }
  EXPECT_EQ(rows, 6);
}

// gasLensLog1p (pure arithmetic, no library call) against the long-double log1pl over the
// arguments the lens produces: δ/g_1 from 0 (at the lens reach) to ~1e7 (R = 1e-2 m against
// s_min = 1e-10 m), here [0, 1e12]: log-uniform from 1e-20 and uniform on [0, 3] (where the
// three branches meet), plus the branch points. Error in ulp of the double result.
TEST(GasLens, Log1pWithinItsUlpBound) {
  auto ulpError = [](double x) {
    const long double ref = log1pl(static_cast<long double>(x));
    const double refD = static_cast<double>(ref);
    const double ulp = std::nextafter(refD, 1e300) - refD;
    return static_cast<double>(std::fabs(static_cast<long double>(k::gasLensLog1p(x)) - ref) /
                               static_cast<long double>(ulp));
  };
  double worst = 0.0;
  std::mt19937_64 rng(20261202);
  std::uniform_real_distribution<double> logU(std::log(1e-20), std::log(1e12));
  std::uniform_real_distribution<double> lin(0.0, 3.0);
  std::vector<double> xs = {0.0,
                            1e-300,
                            0.41421356237309503,
                            std::nextafter(0.41421356237309503, 1.0),
                            std::nextafter(0.41421356237309503, 0.0),
                            1.0,
                            std::nextafter(1.0, 2.0),
                            std::nextafter(1.0, 0.0),
                            std::sqrt(2.0) - 1.0,
                            std::sqrt(2.0),
                            2.0,
                            3.0,
                            1e12};
  for (int m = 0; m < 1000000; ++m) {
    xs.push_back(std::exp(logU(rng)));
    xs.push_back(lin(rng));
  }
  for (double x : xs) {
    const double e = ulpError(x);
    ASSERT_LE(e, k::kGasLensLog1pUlp) << "x " << x;
    worst = std::max(worst, e);
  }
  EXPECT_EQ(k::gasLensLog1p(0.0), 0.0);
  std::printf("gasLensLog1p: worst %.3f ulp over %zu arguments\n", worst, xs.size());
  // gasLensLog (u ≥ 1: the contact branch's g_out/s_min) against logl.
  double worstLog = 0.0;
  std::uniform_real_distribution<double> logV(0.0, std::log(1e12));
  for (int m = 0; m < 1000000; ++m) {
    const double u = m == 0 ? 1.0 : (m == 1 ? 2.0 : std::exp(logV(rng)));
    const long double ref = logl(static_cast<long double>(u));
    const double refD = static_cast<double>(ref);
    const double ulp = std::nextafter(std::max(refD, 1e-300), 1e300) - std::max(refD, 1e-300);
    const double e = static_cast<double>(fabsl(static_cast<long double>(k::gasLensLog(u)) - ref) /
                                         static_cast<long double>(ulp));
    ASSERT_LE(e, k::kGasLensLog1pUlp) << "u " << u;
    worstLog = std::max(worstLog, e);
  }
  EXPECT_EQ(k::gasLensLog(1.0), 0.0);
  std::printf("gasLensLog: worst %.3f ulp\n", worstLog);
}
