#pragma once
/// @file
/// Scalar types of the pair kernels. The kernels of vec3.h, damping.h and lsd_contact.h are
/// templates on their scalar type S: S = double everywhere (host and device), and S = Double2
/// or Double4 in the cpu backend's contact loop, which evaluates two pairs at once, one in each
/// lane of an SSE2 register, or up to four in an AVX register (contacts.h).
///
/// Same bits in every lane: +, −, ×, ÷ and √ are correctly rounded IEEE operations whether they
/// act on one double or on each lane of two, the kernels' expressions are evaluated in the same
/// order for every S, and nothing is contracted into a fused multiply-add (x86-64's baseline,
/// SSE2, has none; Double2 is defined only for builds without FMA instructions, where a compiler
/// could contract scalar and lane code differently). A branch on a value becomes a lane select
/// (laneSelect): both sides are computed, each lane keeps the side its own condition chose.
///
/// The operations the kernels use besides the arithmetic operators, for S = double:
///   laneSqrt(x)          √x
///   laneAny(m)           whether any lane's condition m holds (m: the type of S < S)
///   laneSelect(m, a, b)  per lane, m ? a : b

#include <math.h>

#include "coredem/dem/kernels/common.h"

#if defined(__SSE2__) && !defined(__FMA__) && !defined(__CUDACC__) &&                              \
    (defined(__GNUC__) || defined(__clang__))
#include <emmintrin.h>
/// Defined where kernels::Double2 exists: the cpu backend evaluates pairs two at a time.
#define COREDEM_DEM_DOUBLE2 1
#if defined(__x86_64__)
#include <immintrin.h>
/// Defined where kernels::Double4 exists (functions compiled for AVX only, chosen at run time
/// where the processor has it: contacts.h).
#define COREDEM_DEM_DOUBLE4 1
#endif
#endif

namespace coredem::dem::kernels {

DEM_HD double laneSqrt(double x) {
  return ::sqrt(x);
}
DEM_HD bool laneAny(bool m) {
  return m;
}
DEM_HD double laneSelect(bool m, double a, double b) {
  return m ? a : b;
}

/// Lanes of S (1 for double).
template <class S>
inline constexpr int kLanes = sizeof(S) / sizeof(double);

#if defined(COREDEM_DEM_DOUBLE2)
/// Two doubles in one SSE2 register (GCC/Clang vector extension: the arithmetic operators act
/// per lane, a double operand is broadcast to both lanes, comparisons give a Mask2).
typedef double Double2 __attribute__((vector_size(16)));
/// A comparison's result: per lane all ones (true) or all zeros (false).
using Mask2 = decltype(Double2{} < Double2{});

inline Double2 laneSqrt(Double2 x) {
  return _mm_sqrt_pd(x);
}
inline bool laneAny(Mask2 m) {
  return _mm_movemask_pd(reinterpret_cast<__m128d>(m)) != 0;
}
inline Double2 laneSelect(Mask2 m, Double2 a, Double2 b) {
  return reinterpret_cast<Double2>((reinterpret_cast<Mask2>(a) & m) |
                                   (reinterpret_cast<Mask2>(b) & ~m));
}
#endif

#if defined(COREDEM_DEM_DOUBLE4)
/// Four doubles in one AVX register, as Double2. Its operations are compiled for AVX: use it
/// only in functions with gnu::target("avx"), called where the processor has AVX.
typedef double Double4 __attribute__((vector_size(32)));
using Mask4 = decltype(Double4{} < Double4{});

[[gnu::target("avx")]] inline Double4 laneSqrt(Double4 x) {
  return _mm256_sqrt_pd(x);
}
[[gnu::target("avx")]] inline bool laneAny(Mask4 m) {
  return _mm256_movemask_pd(reinterpret_cast<__m256d>(m)) != 0;
}
[[gnu::target("avx")]] inline Double4 laneSelect(Mask4 m, Double4 a, Double4 b) {
  return reinterpret_cast<Double4>((reinterpret_cast<Mask4>(a) & m) |
                                   (reinterpret_cast<Mask4>(b) & ~m));
}
#endif

} // namespace coredem::dem::kernels
