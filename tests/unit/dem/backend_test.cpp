// Backend tests. The primitives of the cpu backend are tested directly; the conformance
// tests are written once, templated on the backend, and instantiated for cpu and cuda
// (cuda skips when it is not built or no device is present).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <omp.h>

#include "backend/cpu/cpu_exec.h"
#include "coredem/common/check.h"
#include "coredem/dem/dem_system.h"

using namespace coredem::dem;

TEST(CpuBackend, ParallelForTouchesEveryIndexOnce) {
  backend::CpuExec exec;
  exec.threads = 2;
  std::vector<int> hits(10007, 0);
  int* h = hits.data();
  exec.parallelFor(hits.size(), [=](std::size_t i) { h[i] += 1; });
  for (int v : hits)
    ASSERT_EQ(v, 1);
}

// Work hand-out of the cpu backend's loops (ItemClaims): every item once, a thread's own block
// taken from its front in order (it stays on its part of the particle order), and the rest of
// a late thread's block taken by the others from the back (thread 0 starts 50 ms late here, as
// a descheduled thread on a shared machine would).
TEST(CpuBackend, ItemClaimsHandEachItemOutOnceOwnBlockFirst) {
  constexpr int team = 4;
  for (const std::uint32_t count : {0u, 1u, 3u, 4u, 1000u}) {
    for (const bool late : {false, true}) {
      backend::ItemClaims claims;
      const std::uint32_t counts[2] = {count, count / 2};
      std::vector<int> taker(count, -1), taker2(count / 2, -1);
      std::vector<std::vector<std::uint32_t>> order(team);
      int got = 0; // threads OpenMP gave the region
#pragma omp parallel num_threads(team)
      {
        const int t = omp_get_thread_num();
#pragma omp single
        {
          got = omp_get_num_threads();
          claims.init(got, 2, counts);
        }
        if (late && t == 0)
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
        claims.run(0, t, [&](std::uint32_t item) {
          EXPECT_EQ(taker[item], -1) << "item " << item << " handed out twice";
          taker[item] = t;
          order[static_cast<std::size_t>(t)].push_back(item);
          if (!late)
            std::this_thread::sleep_for(std::chrono::microseconds(20));
        });
        claims.run(1, t, [&](std::uint32_t item) { taker2[item] = t; });
      }
      for (std::uint32_t k = 0; k < count; ++k)
        ASSERT_NE(taker[k], -1) << "item " << k << " of " << count << " never handed out";
      for (std::uint32_t k = 0; k < count / 2; ++k)
        ASSERT_NE(taker2[k], -1) << "item " << k << " of the second set never handed out";
      for (int t = 0; t < got; ++t) {
        const std::uint32_t lo = count * t / got, hi = count * (t + 1) / got;
        // Own items first, from the block's front, consecutive.
        std::uint32_t next = lo;
        for (const std::uint32_t item : order[static_cast<std::size_t>(t)]) {
          if (item < lo || item >= hi)
            break;
          EXPECT_EQ(item, next) << "thread " << t << " took its own block out of order";
          ++next;
        }
      }
      if (late && count == 1000u && got > 1) { // the others took over the late thread's items
        int stolen = 0;
        for (std::uint32_t k = 0; k < count / static_cast<std::uint32_t>(got); ++k)
          stolen += taker[k] != 0 ? 1 : 0;
        EXPECT_GT(stolen, 0) << "nobody took over the late thread's items";
      }
    }
  }
}

TEST(CpuBackend, ReduceMaxIsExact) {
  backend::CpuExec exec;
  exec.threads = 2;
  std::vector<double> v(5000);
  for (std::size_t i = 0; i < v.size(); ++i)
    v[i] = std::sin(0.37 * i);
  const double* p = v.data();
  const double r = exec.reduceMax(
      v.size(), [=](std::size_t i) { return p[i]; }, -1e300);
  EXPECT_EQ(r, *std::max_element(v.begin(), v.end()));
  EXPECT_EQ(exec.reduceMax(
                0, [=](std::size_t) { return 1.0; }, -5.0),
            -5.0);
}

TEST(CpuBackend, ExclusiveScan) {
  backend::CpuExec exec;
  const std::vector<std::uint32_t> in{3, 0, 2, 5, 1};
  std::vector<std::uint32_t> out(in.size());
  exec.exclusiveScan(in.data(), out.data(), in.size());
  EXPECT_EQ(out, (std::vector<std::uint32_t>{0, 3, 3, 5, 10}));
}

TEST(CpuBackend, SortByKeyIsStableAndSorted) {
  backend::CpuExec exec;
  const std::size_t n = 20000;
  std::vector<std::uint32_t> keys(n), perm(n);
  std::uint64_t s = 42;
  for (auto& k : keys) {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    k = static_cast<std::uint32_t>((s >> 33) % 517);
  }
  exec.sortByKey(keys.data(), n, 517, perm.data());
  std::vector<int> seen(n, 0);
  for (std::size_t k = 0; k < n; ++k)
    ++seen[perm[k]];
  for (int v : seen)
    ASSERT_EQ(v, 1);
  for (std::size_t k = 1; k < n; ++k) {
    ASSERT_LE(keys[perm[k - 1]], keys[perm[k]]);
    if (keys[perm[k - 1]] == keys[perm[k]]) {
      ASSERT_LT(perm[k - 1], perm[k]); // stable
    }
  }
}

// The radix sort runs its passes on several threads (blocks counted and scattered in (digit,
// block) order): the permutation must equal the serial stable sort for any thread count, key
// range (1 to 4 digit passes) and size (below and above the parallel threshold, odd sizes).
TEST(CpuBackend, RadixSortEqualsStableSortOnAnyThreadCount) {
  std::uint64_t s = 7;
  for (const std::size_t n : {std::size_t{1}, std::size_t{1000}, std::size_t{16383},
                              std::size_t{40001}, std::size_t{250000}}) {
    for (const std::uint32_t numKeys : {1u, 200u, 4961u, 70000u, 3000000000u}) {
      std::vector<std::uint32_t> keys(n);
      for (auto& k : keys) {
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        k = static_cast<std::uint32_t>((s >> 20) % numKeys);
      }
      std::vector<std::uint32_t> expected(n);
      std::iota(expected.begin(), expected.end(), 0u);
      std::stable_sort(expected.begin(), expected.end(),
                       [&](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b]; });
      for (const int threads : {1, 2, 3, 8}) {
        backend::CpuExec exec;
        exec.threads = threads;
        std::vector<std::uint32_t> perm(n, 0xdeadbeefu);
        exec.sortByKeyRadix(keys.data(), n, numKeys, perm.data());
        ASSERT_EQ(perm, expected) << "n " << n << " keys " << numKeys << " threads " << threads;
      }
    }
  }
}

// ---------------------------------------------------------------- conformance, per backend
template <BackendKind K>
struct BackendTag {
  static constexpr BackendKind kind = K;
};

template <class Tag>
class BackendConformance : public ::testing::Test {
protected:
  void SetUp() override {
    if constexpr (Tag::kind == BackendKind::Cuda) {
      if (!cudaBackendBuilt()) {
        GTEST_SKIP() << "CUDA backend not built";
      }
      const CudaProbe cuda = probeCuda();
      if (!cuda.error.empty()) {
        FAIL() << cuda.error; // a broken GPU setup is a failure, not a skip
      }
      if (cuda.devices == 0) {
        GTEST_SKIP() << "no CUDA device: " << cuda.note;
      }
    }
  }
};

using Backends = ::testing::Types<BackendTag<BackendKind::Cpu>, BackendTag<BackendKind::CudaSim>,
                                  BackendTag<BackendKind::Cuda>>;
TYPED_TEST_SUITE(BackendConformance, Backends);

namespace {
DemConfig dilutePairs() {
  DemConfig c;
  c.gravity = {0, 0, 0};
  ParticleSet s;
  s.packing = Packing::Lattice;
  s.regionMin = {0, 0, 0};
  s.regionMax = {6 * 1.2e-3, 6 * 1.2e-3, 6 * 1.2e-3};
  s.spacing = 1.2e-3;
  s.count = 216;
  s.velocityJitter = 0.5;
  s.seed = 7;
  c.particleSets.push_back(s);
  c.addBox({0, 0, 0}, s.regionMax);
  return c;
}
} // namespace

TYPED_TEST(BackendConformance, AgitatedBoxMatchesCpuReference) {
  DemSystem ref(dilutePairs(), BackendKind::Cpu, 1);
  DemSystem sys(dilutePairs(), TypeParam::kind, 2);
  const double dt = sys.dtDemMax();
  for (int k = 0; k < 20; ++k) {
    ref.advance(50 * dt, 50);
    sys.advance(50 * dt, 50);
  }
  EXPECT_GT(ref.stageTimes().rebuilds, 1u);
  const ParticleData a = ref.particles(), b = sys.particles();
  ASSERT_EQ(a.count, b.count);
  std::vector<std::size_t> ia(a.count), ib(b.count);
  for (std::size_t i = 0; i < a.count; ++i)
    ia[a.globalId[i]] = i, ib[b.globalId[i]] = i;
  // cpu vs cpu is bitwise; cuda vs cpu may differ by FMA contraction: 1e-9 m after 1000 steps.
  for (std::size_t g = 0; g < a.count; ++g)
    for (int d = 0; d < 3; ++d)
      ASSERT_NEAR(a.position[3 * ia[g] + d], b.position[3 * ib[g] + d], 1e-9) << "gid " << g;
}

TYPED_TEST(BackendConformance, HeadOnCollisionRestitution) {
  DemConfig c;
  c.gravity = {0, 0, 0};
  ParticleSet s;
  s.packing = Packing::Explicit;
  const double v = 0.4;
  const double dt0 = 1.6075e-6;
  s.positions = {0, 0, 0, 1e-3 + 2 * v * dt0 * 0.5, 0, 0}; // contact starts mid-step
  s.velocities = {v, 0, 0, -v, 0, 0};
  c.particleSets.push_back(s);
  DemSystem sys(c, TypeParam::kind, 1);
  const double dt = sys.dtDemMax();
  for (int k = 0; k < 200; ++k)
    sys.advance(dt, 1);
  const ParticleData p = sys.particles();
  const std::size_t i0 = p.globalId[0] == 0 ? 0 : 1;
  const double rel = p.velocity[3 * (1 - i0)] - p.velocity[3 * i0];
  EXPECT_NEAR(rel / (2 * v), 0.97, 1e-3);
}

TEST(BackendChoice, AutoPicksCudaOnlyWithADevice) {
  DemConfig c;
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.positions = {0, 0, 0};
  c.particleSets.push_back(s);
  DemSystem sys(c, BackendKind::Auto, 1);
  EXPECT_EQ(sys.backendName(), cudaDeviceCount() > 0 ? "cuda" : "cpu");
  EXPECT_EQ(parseBackend("cpu"), BackendKind::Cpu);
  EXPECT_EQ(parseBackend("cuda"), BackendKind::Cuda);
  EXPECT_EQ(parseBackend("auto"), BackendKind::Auto);
  EXPECT_THROW(parseBackend("gpu"), coredem::UserError);
  if (cudaDeviceCount() == 0) {
    EXPECT_THROW(DemSystem(c, BackendKind::Cuda, 1), coredem::UserError); // clear error, no crash
  }
}
