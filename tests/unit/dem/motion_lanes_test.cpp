// The motion of a sub-step (kernels/motion.h, src/motion.h): the symplectic Euler step of
// docs/physics.md §2 (Eqs. 6–7) on one particle against the formulas, and the cpu backend's
// four-lane loop (AVX) against the one-particle path, bit for bit, over ranges whose length is
// not a multiple of four, with a NaN force among them.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "motion.h"

using namespace coredem::dem;
using kernels::Vec3;

namespace {

struct Particles {
  std::vector<double> f, tq, m, r, xref, x, v, w;
  MotionArrays arrays(Vec3 g, double dt) {
    return {f.data(), tq.data(), m.data(), r.data(), xref.data(),
            x.data(), v.data(),  w.data(), g,        dt};
  }
};

Particles randomParticles(std::size_t n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  Particles p;
  for (std::size_t i = 0; i < n; ++i) {
    p.m.push_back(1e-6 * (0.5 + u01(rng)));
    p.r.push_back(4e-4 + 2e-4 * u01(rng));
    for (int c = 0; c < 3; ++c) {
      p.f.push_back(1e-4 * u(rng));
      p.tq.push_back(1e-8 * u(rng));
      p.x.push_back(0.01 * u(rng));
      p.xref.push_back(p.x.back() + 1e-5 * u(rng));
      p.v.push_back(0.5 * u(rng));
      p.w.push_back(300.0 * u(rng));
    }
  }
  return p;
}

void expectSameBits(const std::vector<double>& a, const std::vector<double>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k)
    EXPECT_EQ(std::bit_cast<std::uint64_t>(a[k]), std::bit_cast<std::uint64_t>(b[k]))
        << what << "[" << k << "]: " << a[k] << " vs " << b[k];
}

} // namespace

TEST(Motion, OneStepFollowsTheSymplecticEulerFormulas) {
  // Relative 1e-15: the formulas below in another order (a few roundings of 1.1e-16 each).
  const double m = 2.0e-6, r = 5e-4, dt = 1e-5;
  const Vec3 g{0.0, 0.0, -9.81}, f{1e-4, -2e-4, 3e-4}, tq{1e-9, 2e-9, -3e-9};
  const Vec3 x0{0.01, 0.02, 0.03}, v0{0.1, -0.2, 0.3}, w0{10.0, -20.0, 30.0};
  const Vec3 xref{0.0099, 0.02, 0.0301};
  const kernels::MotionT<double> s = kernels::symplecticEuler(x0, v0, w0, f, tq, m, r, g, xref, dt);
  const double inertia = 0.4 * m * r * r;
  const double vx = v0.x + dt * f.x / m, vy = v0.y + dt * f.y / m, vz = v0.z + dt * (f.z / m + g.z);
  EXPECT_NEAR(s.v.x, vx, 1e-15 * std::abs(vx));
  EXPECT_NEAR(s.v.y, vy, 1e-15 * std::abs(vy));
  EXPECT_NEAR(s.v.z, vz, 1e-15 * std::abs(vz));
  EXPECT_NEAR(s.w.x, w0.x + dt * tq.x / inertia, 1e-15 * std::abs(w0.x));
  EXPECT_NEAR(s.w.y, w0.y + dt * tq.y / inertia, 1e-15 * std::abs(w0.y));
  EXPECT_NEAR(s.w.z, w0.z + dt * tq.z / inertia, 1e-15 * std::abs(w0.z));
  // The position moves with the new velocity (symplectic, not explicit, Euler).
  EXPECT_NEAR(s.x.x, x0.x + dt * vx, 1e-15 * std::abs(x0.x));
  EXPECT_NEAR(s.x.y, x0.y + dt * vy, 1e-15 * std::abs(x0.y));
  EXPECT_NEAR(s.x.z, x0.z + dt * vz, 1e-15 * std::abs(x0.z));
  const double dx = s.x.x - xref.x, dy = s.x.y - xref.y, dz = s.x.z - xref.z;
  EXPECT_NEAR(s.moved2, dx * dx + dy * dy + dz * dz, 1e-15 * (dx * dx + dy * dy + dz * dz));
}

#if defined(COREDEM_DEM_DOUBLE4)
TEST(Motion, FourLanesGiveTheBitsOfTheOneParticlePath) {
  if (!__builtin_cpu_supports("avx"))
    GTEST_SKIP() << "the processor has no AVX: the cpu backend takes one particle at a time";
  std::mt19937_64 rng(20261202);
  const Vec3 g{0.0, 0.0, -9.81};
  for (const std::size_t n : {1u, 3u, 4u, 5u, 8u, 23u, 1030u}) {
    Particles one = randomParticles(n, rng);
    if (n >= 8)
      one.f[3 * 6 + 1] = std::numeric_limits<double>::quiet_NaN(); // particle 6: a NaN force
    const Particles before = one;
    Particles four = one;
    // Ranges that start off a multiple of four, as a thread's chunk may.
    const std::int64_t lo = n > 3 ? 1 : 0, hi = static_cast<std::int64_t>(n);
    const double max1 = moveRange(one.arrays(g, 1.6e-6), lo, hi, false);
    const double max4 = moveRange(four.arrays(g, 1.6e-6), lo, hi, true);
    SCOPED_TRACE("n = " + std::to_string(n));
    EXPECT_EQ(std::bit_cast<std::uint64_t>(max1), std::bit_cast<std::uint64_t>(max4));
    if (n >= 8) {
      EXPECT_EQ(max4, HUGE_VAL) << "a NaN position must force a rebuild";
    }
    expectSameBits(one.x, four.x, "x");
    expectSameBits(one.v, four.v, "v");
    expectSameBits(one.w, four.w, "w");
    // A particle outside the range is not touched.
    if (lo == 1)
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(four.x[c], before.x[c]);
        EXPECT_EQ(four.v[c], before.v[c]);
        EXPECT_EQ(four.w[c], before.w[c]);
      }
  }
}

#endif

TEST(Motion, AnEmptyRangeGivesMinusInfinity) {
  Particles p;
  EXPECT_EQ(moveRange(p.arrays(Vec3{0, 0, 0}, 1e-6), 0, 0, false), -HUGE_VAL);
#if defined(COREDEM_DEM_DOUBLE4)
  if (__builtin_cpu_supports("avx")) {
    EXPECT_EQ(moveRange(p.arrays(Vec3{0, 0, 0}, 1e-6), 0, 0, true), -HUGE_VAL);
  }
#endif
}
