#pragma once
/// @file
/// Scalar types of the pair kernels. The kernels of vec3.h, damping.h and lsd_contact.h are
/// templates on their scalar type S: S = double everywhere (host and device), and, in the cpu
/// backend's contact pass, which evaluates a batch of pairs several at a time (contacts.h,
/// evalPairBatch), one pair per lane of Double2 (SSE2, the x86-64 baseline), Double4 (AVX) or
/// Double8 (AVX-512), the widest the processor has.
///
/// Same bits in every lane: +, −, ×, ÷ and √ are correctly rounded IEEE operations whether they
/// act on one double or on each lane of several, the kernels' expressions are evaluated in the
/// same order for every S, and nothing is contracted into a fused multiply-add: the DEM is
/// compiled with -ffp-contract=off (AVX-512 has FMA instructions, and a compiler could contract
/// scalar and lane code differently), and the lane types are defined only for builds whose
/// baseline has no FMA. A branch on a value becomes a lane select (laneSelect): both sides are
/// computed, each lane keeps the side its own condition chose. The wider types' functions are
/// compiled for their instruction set (gnu::target) and called only where the processor has it.
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
/// Defined where kernels::Double2 exists: the cpu backend evaluates pairs in lanes.
#define COREDEM_DEM_DOUBLE2 1
#if defined(__x86_64__)
#include <immintrin.h>
/// Defined where kernels::Double4 and Double8 exist (for processors with AVX, AVX-512F).
#define COREDEM_DEM_WIDE_LANES 1
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

#if defined(COREDEM_DEM_WIDE_LANES)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi" // inlined into functions of their target
/// Four doubles in one AVX register; call only from functions compiled for AVX.
typedef double Double4 __attribute__((vector_size(32)));
using Mask4 = decltype(Double4{} < Double4{});
/// Eight doubles in one AVX-512 register; call only from functions compiled for AVX-512F.
typedef double Double8 __attribute__((vector_size(64)));
using Mask8 = decltype(Double8{} < Double8{});

[[gnu::target("avx")]] inline Double4 laneSqrt(Double4 x) {
  return _mm256_sqrt_pd(x);
}
[[gnu::target("avx")]] inline bool laneAny(Mask4 m) {
  return _mm256_movemask_pd(reinterpret_cast<__m256d>(m)) != 0;
}
inline Double4 laneSelect(Mask4 m, Double4 a, Double4 b) {
  return reinterpret_cast<Double4>((reinterpret_cast<Mask4>(a) & m) |
                                   (reinterpret_cast<Mask4>(b) & ~m));
}
[[gnu::target("avx512f")]] inline Double8 laneSqrt(Double8 x) {
  return _mm512_mask_sqrt_pd(x, 0xff, x); // all lanes (_mm512_sqrt_pd: GCC 12 warns falsely)
}
[[gnu::target("avx512f")]] inline bool laneAny(Mask8 m) {
  return _mm512_test_epi64_mask(reinterpret_cast<__m512i>(m), reinterpret_cast<__m512i>(m)) != 0;
}
inline Double8 laneSelect(Mask8 m, Double8 a, Double8 b) {
  return reinterpret_cast<Double8>((reinterpret_cast<Mask8>(a) & m) |
                                   (reinterpret_cast<Mask8>(b) & ~m));
}
#pragma GCC diagnostic pop
#endif

} // namespace coredem::dem::kernels
