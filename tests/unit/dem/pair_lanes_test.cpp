// Two owned pairs in the two lanes of Double2 (contacts.h: ownedPair, twoOwnedPairs) give the
// bits of the scalar evaluation, pair by pair: forces, torques, history and the partner shares
// added to the partners' force and torque, for
// sticking and sliding contacts (a lane of each, or both), unequal radii and masses, two
// materials, in the SSE2 version and, where the processor has AVX, in the AVX version.
#include <bit>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "contacts.h"

using namespace coredem::dem;
using kernels::Vec3;

#if defined(COREDEM_DEM_DOUBLE2)

namespace {

using Lsd = kernels::LinearSpringDashpot;

/// An LSD row of the pair table: {k_n, k_t, dampFactor, etatFactor, μ}.
kernels::ContactPair lsdRow(double kn, double kt, double damp, double etat, double mu) {
  return kernels::ContactPair::make<Lsd>(Lsd::Pair{kn, kt, damp, etat, mu});
}

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
  std::vector<kernels::ContactPair> pairs{
      lsdRow(200.0, 100.0, 0.3, 0.5, 0.3), lsdRow(240.0, 120.0, 0.25, 0.5, 0.4),
      lsdRow(240.0, 120.0, 0.25, 0.5, 0.4), lsdRow(300.0, 150.0, 0.2, 0.4, 0.5)};
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

/// twoOwnedPairs' arguments for a case: hc holds the two candidates' history, two materials.
TwoPairArgs<Lsd> argsFor(Case& k, std::vector<double>& hc, std::vector<double>& force,
                         std::vector<double>& torque, double dt, bool avx) {
  return TwoPairArgs<Lsd>{k.x.data(), k.v.data(),   k.w.data(),    k.r.data(),
                          k.m.data(), k.mat.data(), k.half.data(), k.pairs.data(),
                          hc.data(),  force.data(), torque.data(), 2,
                          dt,         avx};
}

struct Expected {
  Vec3 force[2], torque[2], deltaT[2], shareTorque[2];
  bool slides[2];
};

Expected scalarReference(const Case& k, double dt) {
  Expected e{};
  for (int s = 0; s < 2; ++s) {
    const int j = k.half[s];
    const Vec3 d = kernels::load3(k.x.data(), j) - kernels::load3(k.x.data(), 0);
    const Lsd::Pair pp = k.pairs[k.mat[0] * 2 + k.mat[j]].of<Lsd>();
    const OwnedPair<double> op = ownedPair<Lsd, double>(
        d, kernels::dot(d, d), k.r[0], k.r[j], k.m[0], k.m[j], pp, kernels::load3(k.v.data(), 0),
        kernels::load3(k.v.data(), j), kernels::load3(k.w.data(), 0), kernels::load3(k.w.data(), j),
        k.h[s], dt);
    e.force[s] = op.res.force;
    e.torque[s] = op.res.torque;
    e.deltaT[s] = op.res.deltaT;
    e.shareTorque[s] = op.lji * op.res.nxft;
    // Sliding caps the stored displacement at μ|f_n|/k_t.
    e.slides[s] = kernels::norm(op.res.deltaT) < 0.5 * kernels::norm(k.h[s]);
  }
  return e;
}

void checkGroup(bool avx, int cases) {
  std::mt19937_64 rng(avx ? 7 : 11);
  const double dt = 1e-6;
  int slid[2] = {0, 0};
  for (int c = 0; c < cases; ++c) {
    Case k = randomCase(rng, c % 4 == 1 || c % 4 == 3, c % 4 == 2 || c % 4 == 3);
    const Expected e = scalarReference(k, dt);
    std::vector<double> hc{k.h[0].x, k.h[0].y, k.h[0].z, k.h[1].x, k.h[1].y, k.h[1].z};
    // The partners' force and torque hold earlier terms: the shares are added to them.
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<double> force(9), torque(9);
    for (int q = 0; q < 9; ++q) {
      force[q] = 1e-3 * u(rng);
      torque[q] = 1e-7 * u(rng);
    }
    const std::vector<double> force0 = force, torque0 = torque;
    const TwoPairArgs<Lsd> a = argsFor(k, hc, force, torque, dt, avx);
    double out[12];
    twoOwnedPairs(a, 0, 0, 1, out);
    for (int s = 0; s < 2; ++s) {
      expectSameBits(kernels::load3(out, 2 * s), e.force[s], "force", c);
      expectSameBits(kernels::load3(out, 2 * s + 1), e.torque[s], "torque", c);
      const int j = k.half[s];
      expectSameBits(kernels::load3(force.data(), j), kernels::load3(force0.data(), j) - e.force[s],
                     "partner force", c);
      expectSameBits(kernels::load3(torque.data(), j),
                     kernels::load3(torque0.data(), j) + e.shareTorque[s], "partner torque", c);
      expectSameBits(kernels::load3(hc.data(), s), e.deltaT[s], "history", c);
      slid[s] += e.slides[s] ? 1 : 0;
    }
    expectSameBits(kernels::load3(force.data(), 0), kernels::load3(force0.data(), 0),
                   "owner's force (returned, not added)", c);
  }
  // Each lane slid in about half of the cases, alone or with the other.
  EXPECT_GT(slid[0], cases / 4);
  EXPECT_GT(slid[1], cases / 4);
}

} // namespace

TEST(PairLanes, TwoPairsGiveTheScalarBitsSse2) {
  checkGroup(false, 4000);
}

TEST(PairLanes, TwoPairsGiveTheScalarBitsAvx) {
  if (!cpuHasAvx())
    GTEST_SKIP() << "the processor has no AVX";
  checkGroup(true, 4000);
}

#if defined(COREDEM_DEM_DOUBLE4)
// Three and four pairs through ownedPairs: in the four AVX lanes (fourOwnedPairsAvx; the fourth
// lane of a group of three changes nothing) and, without AVX, two lanes and the scalar path:
// the bits of the scalar evaluation, pair by pair, sticking and sliding, two materials.
TEST(PairLanes, FourLanesGiveTheScalarBits) {
  if (!cpuHasAvx())
    GTEST_SKIP() << "the processor has no AVX";
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0), u01(0.0, 1.0);
  const double dt = 1e-6;
  int slid = 0;
  for (int c = 0; c < 4000; ++c) {
    const int count = 3 + c % 2;
    const bool avx = c % 4 < 2;
    // Particle 0 owns candidates q = 0..count-1 (particles 1..count), all in contact.
    const int np = count + 1;
    std::vector<double> x, v, w, r, m;
    std::vector<std::int32_t> mat(np), half;
    for (int p = 0; p < np; ++p) {
      r.push_back(4e-4 + 2e-4 * u01(rng));
      m.push_back(1e-6 * (0.5 + u01(rng)));
      mat[p] = static_cast<std::int32_t>(rng() % 2);
      for (int k = 0; k < 3; ++k) {
        v.push_back(0.3 * u(rng));
        w.push_back(200.0 * u(rng));
      }
    }
    x = {0.01 * u(rng), 0.01 * u(rng), 0.01 * u(rng)};
    for (int p = 1; p < np; ++p) {
      Vec3 n{u(rng), u(rng), u(rng)};
      n = (1.0 / kernels::norm(n)) * n;
      const double l = (0.98 + 0.019 * u01(rng)) * (r[0] + r[p]);
      x.push_back(x[0] + l * n.x);
      x.push_back(x[1] + l * n.y);
      x.push_back(x[2] + l * n.z);
      half.push_back(p);
    }
    std::vector<double> hc;
    for (int k = 0; k < count; ++k) {
      const double a = (c / 2 + k) % 3 == 0 ? 1e-3 : 1e-7; // slides : sticks
      for (int d = 0; d < 3; ++d)
        hc.push_back(a * u(rng));
    }
    std::vector<double> force(3 * np), torque(3 * np);
    for (int k = 0; k < 3 * np; ++k) {
      force[k] = 1e-3 * u(rng);
      torque[k] = 1e-7 * u(rng);
    }
    const std::vector<double> hc0 = hc, force0 = force, torque0 = torque;
    std::vector<kernels::ContactPair> pairs{
        lsdRow(200.0, 100.0, 0.3, 0.5, 0.3), lsdRow(240.0, 120.0, 0.25, 0.5, 0.4),
        lsdRow(240.0, 120.0, 0.25, 0.5, 0.4), lsdRow(300.0, 150.0, 0.2, 0.4, 0.5)};
    const TwoPairArgs<Lsd> a{x.data(),      v.data(),    w.data(),     r.data(),  m.data(),
                             mat.data(),    half.data(), pairs.data(), hc.data(), force.data(),
                             torque.data(), 2,           dt,           avx};
    const std::uint32_t q[4] = {0, 1, 2, 3};
    double out[24];
    ownedPairs(a, 0, q, count, out);
    for (int k = 0; k < count; ++k) {
      const int j = half[k];
      const Vec3 d = kernels::load3(x.data(), j) - kernels::load3(x.data(), 0);
      const Lsd::Pair pp = pairs[mat[0] * 2 + mat[j]].of<Lsd>();
      const OwnedPair<double> op = ownedPair<Lsd, double>(
          d, kernels::dot(d, d), r[0], r[j], m[0], m[j], pp, kernels::load3(v.data(), 0),
          kernels::load3(v.data(), j), kernels::load3(w.data(), 0), kernels::load3(w.data(), j),
          kernels::load3(hc0.data(), k), dt);
      expectSameBits(kernels::load3(out, 2 * k), op.res.force, "force", c);
      expectSameBits(kernels::load3(out, 2 * k + 1), op.res.torque, "torque", c);
      expectSameBits(kernels::load3(hc.data(), k), op.res.deltaT, "history", c);
      expectSameBits(kernels::load3(force.data(), j),
                     kernels::load3(force0.data(), j) - op.res.force, "partner force", c);
      expectSameBits(kernels::load3(torque.data(), j),
                     kernels::load3(torque0.data(), j) + op.lji * op.res.nxft, "partner torque", c);
      slid += kernels::norm(op.res.deltaT) < 0.5 * kernels::norm(kernels::load3(hc0.data(), k));
    }
    expectSameBits(kernels::load3(force.data(), 0), kernels::load3(force0.data(), 0),
                   "owner's force (returned, not added)", c);
  }
  EXPECT_GT(slid, 2000) << "too few sliding lanes: the Coulomb branch is not exercised";
}
#endif

#else
TEST(PairLanes, NotBuiltWithoutDouble2) {
  GTEST_SKIP() << "kernels::Double2 needs SSE2 without FMA (x86-64 baseline)";
}
#endif
