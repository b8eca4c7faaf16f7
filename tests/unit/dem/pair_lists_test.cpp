// PairLists (pair_lists.h): the slabs that let the cpu contact pass add each pair's share
// straight to the partner. A slab
// partition is valid when every pair joins particles of the same or of adjacent slabs; it must
// hold for any particle order (a badly sorted one only gives larger slabs). (The colours and
// low-list owners are built for the gather backends only; that they give the scatter's order
// is checked by the cpu vs cuda-sim tests, contact_pairs_test.cpp and backend_conformance.)
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "backend/cpu/cpu_exec.h"
#include "pair_lists.h"

using namespace coredem::dem;
using backend::CpuExec;

namespace {

/// n particles at random points of a box, neighbours within `cut`, numbered in `order`
/// (a permutation of the sorted-by-z numbering, or the identity); gids shuffled.
void fillRandomGraph(ParticleStore<CpuExec>& p, std::size_t n, double cut, bool shuffleOrder,
                     unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> x(3 * n);
  for (auto& v : x)
    v = u(rng);
  // Sorted by z (then a coarse x): close particles have close indices, as after a rebuild.
  std::vector<std::size_t> idx(n);
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) {
    return std::make_pair(std::floor(x[3 * a + 2] / cut), x[3 * a]) <
           std::make_pair(std::floor(x[3 * b + 2] / cut), x[3 * b]);
  });
  if (shuffleOrder)
    std::shuffle(idx.begin(), idx.end(), rng);
  std::vector<std::int64_t> gids(n);
  std::iota(gids.begin(), gids.end(), 0);
  std::shuffle(gids.begin(), gids.end(), rng);
  std::vector<std::vector<std::int32_t>> nb(n);
  int width = 1;
  for (std::size_t a = 0; a < n; ++a) {
    for (std::size_t b = 0; b < n; ++b) {
      if (a == b)
        continue;
      double d2 = 0.0;
      for (int c = 0; c < 3; ++c) {
        const double d = x[3 * idx[a] + c] - x[3 * idx[b] + c];
        d2 += d * d;
      }
      if (d2 < cut * cut)
        nb[a].push_back(static_cast<std::int32_t>(b));
    }
    width = std::max(width, static_cast<int>(nb[a].size()));
  }
  p.allocate(n, 0, 4, width);
  for (std::size_t a = 0; a < n; ++a) {
    p.gid.h()[a] = gids[a];
    p.nbCount.h()[a] = static_cast<std::int32_t>(nb[a].size());
    for (std::size_t k = 0; k < nb[a].size(); ++k)
      p.nbList.h()[a * width + k] = nb[a][k];
  }
  p.toDevice(kGid | kNbCount | kNbList);
}

void expectValidSlabs(ParticleStore<CpuExec>& p, PairLists<CpuExec>& pl) {
  const std::size_t n = p.n;
  const int slabs = pl.slabs();
  ASSERT_GE(slabs, 1);
  const std::uint32_t* start = pl.slabStart();
  EXPECT_EQ(start[0], 0u);
  EXPECT_EQ(start[slabs], n);
  std::vector<int> slabOf(n, -1);
  for (int s = 0; s < slabs; ++s) {
    ASSERT_LT(start[s], start[s + 1]) << "slab " << s << " is empty";
    if (s + 1 < slabs) {
      EXPECT_GE(start[s + 1] - start[s], PairLists<CpuExec>::kMinSlab) << "slab " << s;
    }
    for (std::uint32_t i = start[s]; i < start[s + 1]; ++i)
      slabOf[i] = s;
  }
  const int M = p.M;
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < p.nbCount.h()[i]; ++a) {
      const auto j = static_cast<std::size_t>(p.nbList.h()[i * M + a]);
      ASSERT_LE(std::abs(slabOf[i] - slabOf[j]), 1)
          << "pair " << i << "-" << j << " skips a slab (" << slabOf[i] << ", " << slabOf[j] << ")";
    }
  }
}

} // namespace

TEST(PairListSlabs, SortedOrderGivesManyThinSlabsThatNoPairSkips) {
  ParticleStore<CpuExec> p;
  fillRandomGraph(p, 6000, 0.08, false, 1); // a layer of reach: ~500 particles, ~kMinSlab
  CpuExec exec;
  PairLists<CpuExec> pl;
  pl.ensure(exec, p);
  expectValidSlabs(p, pl);
  EXPECT_GE(pl.slabs(), 5); // a sorted order cuts into slabs of about one layer of reach
}

TEST(PairListSlabs, AnyOrderGivesValidSlabs) {
  ParticleStore<CpuExec> p;
  fillRandomGraph(p, 3000, 0.08, true, 2);
  CpuExec exec;
  PairLists<CpuExec> pl;
  pl.ensure(exec, p);
  expectValidSlabs(p, pl);
}

TEST(PairListSlabs, DiluteAndTinySystems) {
  for (const std::size_t n :
       {std::size_t{1}, std::size_t{7}, std::size_t{700}, std::size_t{5000}}) {
    ParticleStore<CpuExec> p;
    fillRandomGraph(p, n, n > 1000 ? 0.01 : 0.2, false, 3); // 5000: hardly any neighbours
    CpuExec exec;
    PairLists<CpuExec> pl;
    pl.ensure(exec, p);
    expectValidSlabs(p, pl);
    constexpr std::size_t kMin = PairLists<CpuExec>::kMinSlab;
    if (n <= kMin) {
      EXPECT_EQ(pl.slabs(), 1) << "n = " << n;
    } else if (n == 5000) { // almost no neighbours: slabs of kMinSlab particles
      EXPECT_GE(pl.slabs(), static_cast<int>(n / kMin) - 1);
      EXPECT_LE(pl.slabs(), static_cast<int>((n + kMin - 1) / kMin));
    }
  }
}

TEST(PairListSlabs, ColourZeroClearsEverySlabOnceAndAllItReaches) {
  // The cpu contact pass clears force and torque inside its first colour (slabsClearedBy):
  // every slab exactly once, and each slab of colour 0 clears at least the slabs its own pairs
  // reach (s − 1 .. s + 1) before adding to them. The other slabs that add to a cleared slab are
  // of colours 1 and 2 and within two of the slab of colour 0 that cleared it: they wait for it
  // (CpuExec::reduceMaxOverSlabRanges).
  for (int slabs = 1; slabs <= 14; ++slabs) {
    std::vector<int> cleared(static_cast<std::size_t>(slabs), 0);
    for (int s = 0; s < slabs; s += 3) {
      const SlabSpan span = slabsClearedBy(s, slabs);
      ASSERT_LE(0, span.first);
      ASSERT_LE(span.last, slabs);
      EXPECT_LE(span.first, std::max(s - 1, 0)) << slabs << " slabs, slab " << s;
      EXPECT_GE(span.last, std::min(s + 2, slabs)) << slabs << " slabs, slab " << s;
      for (int k = span.first; k < span.last; ++k) {
        ++cleared[static_cast<std::size_t>(k)];
        EXPECT_LE(std::abs(k - s), 2)
            << "slab " << k << " is cleared by slab " << s << ", which it does not wait for";
      }
    }
    for (int k = 0; k < slabs; ++k)
      EXPECT_EQ(cleared[static_cast<std::size_t>(k)], 1) << slabs << " slabs, slab " << k;
  }
}
