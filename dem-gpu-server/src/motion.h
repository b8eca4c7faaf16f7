#pragma once
/// @file
/// The motion loop of a sub-step (EngineImpl::integrate): every particle moved by
/// kernels::symplecticEuler, and the largest squared displacement since the last neighbour-list
/// build. One particle at a time on every backend; on the cpu backend, where the processor has
/// AVX, four at a time in the lanes of kernels::Double4: the rows of four consecutive particles
/// (12 consecutive doubles per field) are transposed into one register per component, moved,
/// and transposed back; the same operations per lane, so the same bits as the one-particle
/// path (tests/unit/dem/motion_lanes_test.cpp).

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include <math.h>

#include "coredem/dem/kernels/lanes.h"
#include "coredem/dem/kernels/motion.h"
#include "coredem/dem/kernels/vec3.h"

namespace coredem::dem {

/// What the motion loop reads (forces, torques, masses, radii, positions at the last build) and
/// writes (positions, velocities, angular velocities): rows of 3 doubles per particle, or one.
struct MotionArrays {
  const double* f;
  const double* tq;
  const double* m;
  const double* r;
  const double* xref;
  double* x;
  double* v;
  double* w;
  kernels::Vec3 g;
  double dt;
};

/// Moves particle i; returns its squared displacement since the last build, +∞ if that is NaN
/// (a NaN position forces a rebuild, which reports it).
DEM_HD double moveParticle(const MotionArrays& a, long long i) {
  using namespace kernels;
  const MotionT<double> s =
      symplecticEuler(load3(a.x, i), load3(a.v, i), load3(a.w, i), load3(a.f, i), load3(a.tq, i),
                      a.m[i], a.r[i], a.g, load3(a.xref, i), a.dt);
  store3(a.w, i, s.w);
  store3(a.v, i, s.v);
  store3(a.x, i, s.x);
  return s.moved2 == s.moved2 ? s.moved2 : HUGE_VAL;
}

/// Whether Exec runs a loop as ranges of indices (cpu: reduceMaxOverRangesInto), so that the
/// motion loop can take four particles at a time.
template <class Exec>
inline constexpr bool kRangeLoops = requires(const Exec& e, double* o) {
  e.reduceMaxOverRangesInto(
      std::size_t{0}, [](std::int64_t, std::int64_t) { return 0.0; }, 0.0, o);
};

#if defined(COREDEM_DEM_DOUBLE4)
/// The rows i..i+3 of p (3 doubles each), one register per component.
[[gnu::target("avx")]] inline kernels::Vec3T<kernels::Double4> loadRows4(const double* p,
                                                                         long long i) {
  using D = kernels::Double4;
  const double* q = p + 3 * i;
  const __m256d a = _mm256_loadu_pd(q);                    // x0 y0 z0 x1
  const __m256d b = _mm256_loadu_pd(q + 4);                // y1 z1 x2 y2
  const __m256d c = _mm256_loadu_pd(q + 8);                // z2 x3 y3 z3
  const __m256d xy02 = _mm256_permute2f128_pd(a, b, 0x30); // x0 y0 x2 y2
  const __m256d zx13 = _mm256_permute2f128_pd(a, c, 0x21); // z0 x1 z2 x3
  const __m256d yz13 = _mm256_permute2f128_pd(b, c, 0x30); // y1 z1 y3 z3
  return {reinterpret_cast<D>(_mm256_shuffle_pd(xy02, zx13, 0xA)),
          reinterpret_cast<D>(_mm256_shuffle_pd(xy02, yz13, 0x5)),
          reinterpret_cast<D>(_mm256_shuffle_pd(zx13, yz13, 0xA))};
}

/// Stores the four vectors of u into the rows i..i+3 of p (loadRows4's inverse).
[[gnu::target("avx")]] inline void storeRows4(double* p, long long i,
                                              kernels::Vec3T<kernels::Double4> u) {
  const __m256d x = reinterpret_cast<__m256d>(u.x);
  const __m256d y = reinterpret_cast<__m256d>(u.y);
  const __m256d z = reinterpret_cast<__m256d>(u.z);
  const __m256d xy02 = _mm256_shuffle_pd(x, y, 0x0); // x0 y0 x2 y2
  const __m256d zx13 = _mm256_shuffle_pd(z, x, 0xA); // z0 x1 z2 x3
  const __m256d yz13 = _mm256_shuffle_pd(y, z, 0xF); // y1 z1 y3 z3
  double* q = p + 3 * i;
  _mm256_storeu_pd(q, _mm256_permute2f128_pd(xy02, zx13, 0x20));     // x0 y0 z0 x1
  _mm256_storeu_pd(q + 4, _mm256_permute2f128_pd(yz13, xy02, 0x30)); // y1 z1 x2 y2
  _mm256_storeu_pd(q + 8, _mm256_permute2f128_pd(zx13, yz13, 0x31)); // z2 x3 y3 z3
}

/// moveRange for a processor with AVX.
[[gnu::target("avx"), gnu::flatten]] inline double moveRangeAvx(const MotionArrays& a,
                                                                std::int64_t lo, std::int64_t hi) {
  using namespace kernels;
  using D = Double4;
  double moved2 = -HUGE_VAL;
  std::int64_t i = lo;
  for (; i + 4 <= hi; i += 4) {
    const D m = reinterpret_cast<D>(_mm256_loadu_pd(a.m + i));
    const D r = reinterpret_cast<D>(_mm256_loadu_pd(a.r + i));
    const MotionT<D> s = symplecticEuler<D>(loadRows4(a.x, i), loadRows4(a.v, i), loadRows4(a.w, i),
                                            loadRows4(a.f, i), loadRows4(a.tq, i), m, r, a.g,
                                            loadRows4(a.xref, i), a.dt);
    storeRows4(a.w, i, s.w);
    storeRows4(a.v, i, s.v);
    storeRows4(a.x, i, s.x);
    for (int k = 0; k < 4; ++k) {
      const double d2 = s.moved2[k];
      moved2 = std::max(moved2, d2 == d2 ? d2 : HUGE_VAL);
    }
  }
  for (; i < hi; ++i)
    moved2 = std::max(moved2, moveParticle(a, i));
  return moved2;
}
#endif

/// Moves the particles [lo, hi); returns the largest squared displacement (moveParticle), −∞
/// for an empty range.
inline double moveRange(const MotionArrays& a, std::int64_t lo, std::int64_t hi, bool avx) {
#if defined(COREDEM_DEM_DOUBLE4)
  if (avx)
    return moveRangeAvx(a, lo, hi);
#endif
  (void)avx;
  double moved2 = -HUGE_VAL;
  for (std::int64_t i = lo; i < hi; ++i)
    moved2 = std::max(moved2, moveParticle(a, i));
  return moved2;
}

} // namespace coredem::dem
