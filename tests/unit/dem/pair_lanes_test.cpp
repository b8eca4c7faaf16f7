// A batch of owned pairs evaluated in SIMD lanes (contacts.h: PairBatch, evalPairBatch) gives the
// bits of the scalar evaluation (ownedPair<double>, the other backends' path), pair by pair:
// forces, torques, new tangential history and the partner's torque, for sticking and sliding
// contacts in any mix across the lanes, unequal radii and masses, two materials, every batch
// size from 1 to the capacity (full groups and the narrower tails) and every lane count the
// processor runs (1, 2, 4 with AVX, 8 with AVX-512F).
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "contacts.h"

using namespace coredem::dem;
using kernels::Vec3;

#if defined(COREDEM_DEM_DOUBLE2)

namespace {

void expectSameBits(double a, double b, const char* what, int c) {
  EXPECT_EQ(std::bit_cast<std::uint64_t>(a), std::bit_cast<std::uint64_t>(b))
      << what << " (case " << c << "): " << a << " vs " << b;
}

void expectSameBits(Vec3 a, Vec3 b, const char* what, int c) {
  expectSameBits(a.x, b.x, what, c);
  expectSameBits(a.y, b.y, what, c);
  expectSameBits(a.z, b.z, what, c);
}

/// Particle 0 owns two candidates (q = 0, 1: particles 1 and 2), both in contact.
struct Case {
  std::vector<double> x, v, w, r, m;
  std::vector<std::int32_t> mat{0, 0, 0}, half{1, 2};
  std::vector<PairProps> pairs{
      PairProps{200.0, 100.0, 0.3, 0.5, 0.3}, PairProps{240.0, 120.0, 0.25, 0.5, 0.4},
      PairProps{240.0, 120.0, 0.25, 0.5, 0.4}, PairProps{300.0, 150.0, 0.2, 0.4, 0.5}};
  Vec3 h[2];
};

Case randomCase(std::mt19937_64& rng, bool slide0, bool slide1) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  Case k;
  for (int p = 0; p < 3; ++p) {
    k.r.push_back(4e-4 + 2e-4 * u01(rng));
    k.m.push_back(1e-6 * (0.5 + u01(rng)));
    k.mat[p] = static_cast<std::int32_t>(rng() % 2);
    for (int c = 0; c < 3; ++c) {
      k.v.push_back(0.3 * u(rng));
      k.w.push_back(200.0 * u(rng));
    }
  }
  k.x = {0.01 * u(rng), 0.01 * u(rng), 0.01 * u(rng)};
  for (int p = 1; p < 3; ++p) { // at distance (1 − 2 %) (r_0 + r_p) in a random direction
    Vec3 n{u(rng), u(rng), u(rng)};
    n = (1.0 / kernels::norm(n)) * n;
    const double l = (0.98 + 0.019 * u01(rng)) * (k.r[0] + k.r[p]);
    for (int c = 0; c < 3; ++c)
      k.x.push_back(k.x[c] + l * (c == 0 ? n.x : c == 1 ? n.y : n.z));
  }
  // Tangential history: a millimetre slides (|k_t δ_t| ≫ μ|f_n|), a micrometre or less sticks.
  const bool slide[2] = {slide0, slide1};
  for (int s = 0; s < 2; ++s) {
    const double a = slide[s] ? 1e-3 : 1e-7;
    k.h[s] = Vec3{a * u(rng), a * u(rng), a * u(rng)};
  }
  return k;
}

/// The pair (0, p) of a random case as one batch column c; its expected results.
struct Column {
  Vec3 force, torque, deltaT, shareTorque;
  bool slides;
};

Column fillColumn(PairBatch& b, int c, const Case& k, int p, double dt) {
  using B = PairBatch;
  const int j = k.half[p];
  const Vec3 d = kernels::load3(k.x.data(), j) - kernels::load3(k.x.data(), 0);
  const PairProps& pp = k.pairs[k.mat[0] * 2 + k.mat[j]];
  const double in[B::kIn] = {d.x,
                             d.y,
                             d.z,
                             kernels::dot(d, d),
                             k.r[0],
                             k.r[j],
                             k.m[0],
                             k.m[j],
                             pp.kn,
                             pp.kt,
                             pp.dampFactor,
                             pp.etatFactor,
                             pp.mu,
                             k.v[0],
                             k.v[1],
                             k.v[2],
                             k.v[3 * j],
                             k.v[3 * j + 1],
                             k.v[3 * j + 2],
                             k.w[0],
                             k.w[1],
                             k.w[2],
                             k.w[3 * j],
                             k.w[3 * j + 1],
                             k.w[3 * j + 2],
                             k.h[p].x,
                             k.h[p].y,
                             k.h[p].z};
  for (int f = 0; f < B::kIn; ++f)
    b.in[f][c] = in[f];
  const OwnedPair<double> op =
      ownedPair(d, kernels::dot(d, d), k.r[0], k.r[j], k.m[0], k.m[j], pp.kn, pp.kt, pp.dampFactor,
                pp.etatFactor, pp.mu, kernels::load3(k.v.data(), 0), kernels::load3(k.v.data(), j),
                kernels::load3(k.w.data(), 0), kernels::load3(k.w.data(), j), k.h[p], dt);
  // Sliding caps the stored displacement at μ|f_n|/k_t.
  return {op.res.force, op.res.torque, op.res.deltaT, op.lji * op.res.nxft,
          kernels::norm(op.res.deltaT) < 0.5 * kernels::norm(k.h[p])};
}

Vec3 outColumn(const PairBatch& b, int f, int c) {
  return Vec3{b.out[f][c], b.out[f + 1][c], b.out[f + 2][c]};
}

/// Batches of every size 1..capacity, `rounds` times, evaluated `lanes` at a time.
void checkBatches(int lanes, int rounds) {
  using B = PairBatch;
  std::mt19937_64 rng(7 + lanes);
  const double dt = 1e-6;
  int slid = 0, columns = 0;
  for (int round = 0; round < rounds; ++round) {
    for (int count = 1; count <= B::kCapacity; ++count) {
      B b;
      std::vector<Column> expected;
      for (int c = 0; c < count; ++c) {
        const bool slide = (rng() % 2) == 0;
        const Case k = randomCase(rng, slide, !slide);
        expected.push_back(fillColumn(b, c, k, static_cast<int>(rng() % 2), dt));
      }
      evalPairBatch(b, count, dt, lanes);
      for (int c = 0; c < count; ++c) {
        const int id = 1000 * count + c;
        expectSameBits(outColumn(b, B::Fx, c), expected[c].force, "force", id);
        expectSameBits(outColumn(b, B::Tx, c), expected[c].torque, "torque", id);
        expectSameBits(outColumn(b, B::DTx, c), expected[c].deltaT, "history", id);
        expectSameBits(outColumn(b, B::Sx, c), expected[c].shareTorque, "partner torque", id);
        slid += expected[c].slides ? 1 : 0;
        ++columns;
      }
      if (::testing::Test::HasFailure())
        return;
    }
  }
  // About half of the columns slid, mixed with sticking ones in the same groups.
  EXPECT_GT(slid, columns / 4);
  EXPECT_LT(slid, 3 * columns / 4);
}

} // namespace

TEST(PairLanes, ScalarBatchGivesTheScalarBits) {
  checkBatches(1, 2);
}

TEST(PairLanes, TwoLanesGiveTheScalarBits) {
  checkBatches(2, 2);
}

TEST(PairLanes, FourLanesGiveTheScalarBits) {
  if (widestPairLanes() < 4)
    GTEST_SKIP() << "the processor has no AVX";
  checkBatches(4, 2);
}

TEST(PairLanes, EightLanesGiveTheScalarBits) {
  if (widestPairLanes() < 8)
    GTEST_SKIP() << "the processor has no AVX-512F";
  checkBatches(8, 2);
}

TEST(PairLanes, LaneCountOverrideIsCappedAtTheProcessor) {
  const int widest = widestPairLanes();
  EXPECT_TRUE(widest == 2 || widest == 4 || widest == 8);
  ::setenv("COREDEM_DEM_PAIR_LANES", "1", 1);
  EXPECT_EQ(pairLanesToUse(), 1);
  ::setenv("COREDEM_DEM_PAIR_LANES", "64", 1); // not a lane count: ignored
  EXPECT_EQ(pairLanesToUse(), widest);
  ::setenv("COREDEM_DEM_PAIR_LANES", "8", 1);
  EXPECT_EQ(pairLanesToUse(), widest);
  ::unsetenv("COREDEM_DEM_PAIR_LANES");
  EXPECT_EQ(pairLanesToUse(), widest);
}

#else
TEST(PairLanes, NotBuiltWithoutDouble2) {
  GTEST_SKIP() << "the SIMD lanes need SSE2 without FMA (x86-64 baseline)";
}
#endif
