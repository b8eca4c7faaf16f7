// Contact pairs evaluated once (contacts.h): the owner (smaller global id) evaluates each pair,
// the partner gathers its share. Checked against a reference that evaluates every pair from both
// sides, for thread-count independence on a dense bed, and for state files whose history holds
// both sides of a contact (the layout before format version 3).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "backend/cpu/cpu_exec.h"
#include "contacts.h"
#include "coredem/dem/kernels/damping.h"
#include "coredem/dem/kernels/lsd_contact.h"
#include "coredem/dem/kernels/wall_contact.h"
#include "engine.h"

using namespace coredem::dem;
using kernels::Vec3;

namespace {

using Lsd = kernels::LinearSpringDashpot;

/// An LSD row of the pair table: {k_n, k_t, dampFactor, etatFactor, μ}.
kernels::ContactPair lsdRow(double kn, double kt, double damp, double etat, double mu) {
  return kernels::ContactPair::make<Lsd>(Lsd::Pair{kn, kt, damp, etat, mu});
}

constexpr int kSlots = 12;
constexpr double kDiameter = 1e-3;
constexpr double kPi = 3.14159265358979323846;

/// Two materials; pairs mix them as DemSystem does (symmetric table).
EngineSetup denseSetup(int threads) {
  EngineSetup s;
  s.nMaterials = 2;
  const kernels::ContactPair a = lsdRow(200.0, 100.0, 0.3, 0.5, 0.3);
  const kernels::ContactPair b = lsdRow(300.0, 150.0, 0.2, 0.5, 0.5);
  const kernels::ContactPair ab = lsdRow(240.0, 120.0, 0.3, 0.5, 0.3);
  s.pairs = {a, ab, ab, b};
  s.walls = {kernels::planeWall(Vec3{0, 0, 0}, Vec3{0, 0, 1})};
  s.maxRadius = 0.55 * kDiameter;
  s.skin = 0.1 * kDiameter;
  s.historySlots = kSlots;
  s.neighbourSlots = 32;
  s.threads = threads;
  return s;
}

/// side³ particles on a compressed, jittered lattice (spacing 0.95 d): every lattice neighbour
/// overlaps, the bottom layer touches the floor; two radii and two materials; random motion.
/// Given in shuffled order with shuffled global ids so that ownership differs from index order.
HostState denseState(int side) {
  HostState s;
  const auto n = static_cast<std::size_t>(side * side * side);
  s.n = n;
  s.historySlots = kSlots;
  s.neighbourSlots = 32;
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<std::int64_t> gids(n);
  for (std::size_t i = 0; i < n; ++i)
    gids[i] = static_cast<std::int64_t>(i);
  std::shuffle(gids.begin(), gids.end(), rng);
  const double h = 0.95 * kDiameter;
  for (std::size_t i = 0; i < n; ++i) {
    const int ix = static_cast<int>(i % side), iy = static_cast<int>((i / side) % side),
              iz = static_cast<int>(i / (side * side));
    const double c[3] = {h * ix, h * iy, 0.48 * kDiameter + h * iz};
    for (int d = 0; d < 3; ++d) {
      s.pos.push_back(c[d] + 0.01 * kDiameter * u(rng));
      s.vel.push_back(0.05 * u(rng));
      s.omega.push_back(50.0 * u(rng));
    }
    const bool big = (ix + iy + iz) % 2 == 0;
    const double r = big ? 0.5 * kDiameter : 0.49 * kDiameter;
    s.radius.push_back(r);
    s.density.push_back(2500.0);
    s.mass.push_back(2500.0 * 4.0 / 3.0 * kPi * r * r * r);
    s.temperature.push_back(300.0);
    s.material.push_back(big ? 0 : 1);
    s.gid.push_back(gids[i]);
  }
  s.xref = s.pos;
  fillDefaults(s);
  checkShapes(s, "denseState");
  return s;
}

std::map<std::int64_t, std::size_t> rowByGid(const HostState& s) {
  std::map<std::int64_t, std::size_t> m;
  for (std::size_t i = 0; i < s.n; ++i)
    m[s.gid[i]] = i;
  return m;
}

/// δ_t stored in particle i's slots under `key`, and whether there is one.
bool slotOf(const HostState& s, std::size_t i, std::int64_t key, Vec3& d) {
  for (int k = 0; k < s.historySlots; ++k) {
    const std::size_t q = i * s.historySlots + static_cast<std::size_t>(k);
    if (s.histKey[q] == key) {
      d = Vec3{s.histDisp[3 * q], s.histDisp[3 * q + 1], s.histDisp[3 * q + 2]};
      return true;
    }
  }
  return false;
}

Vec3 at(const std::vector<double>& v, std::size_t i) {
  return Vec3{v[3 * i], v[3 * i + 1], v[3 * i + 2]};
}

void expectBitwiseEqual(const HostState& a, const HostState& b) {
  EXPECT_EQ(a.gid, b.gid);
  EXPECT_EQ(a.pos, b.pos);
  EXPECT_EQ(a.vel, b.vel);
  EXPECT_EQ(a.omega, b.omega);
  EXPECT_EQ(a.force, b.force);
  EXPECT_EQ(a.torque, b.torque);
  EXPECT_EQ(a.histKey, b.histKey);
  EXPECT_EQ(a.contacts, b.contacts);
  // δ_t of the slots in use (an emptied slot keeps a stale δ_t that is never read).
  ASSERT_EQ(a.histDisp.size(), b.histDisp.size());
  for (std::size_t q = 0; q < a.histKey.size(); ++q) {
    if (a.histKey[q] == -1)
      continue;
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(a.histDisp[3 * q + c], b.histDisp[3 * q + c]) << "slot " << q;
  }
}

} // namespace

TEST(ContactPairs, ForcesMatchAReferenceEvaluatingBothSides) {
  const EngineSetup setup = denseSetup(2);
  auto engine = makeCpuEngine(setup);
  engine->setState(denseState(6));
  const double dt = 2e-6;
  for (int k = 0; k < 40; ++k) // tangential history builds up (some contacts slide)
    engine->subStep(dt);
  const HostState s0 = engine->state();
  engine->subStep(dt);
  const HostState s1 = engine->state(); // forces of this sub-step: at s0's positions
  const auto row1 = rowByGid(s1);

  // Reference: every pair evaluated from each side, the history of side i taken from the
  // owner's slot (negated for the partner).
  double fMax = 0.0, tMax = 0.0, fErr = 0.0, tErr = 0.0, dErr = 0.0, dMax = 0.0;
  std::size_t pairContacts = 0, sliding = 0;
  for (std::size_t i = 0; i < s0.n; ++i) {
    using namespace kernels;
    const Vec3 xi = at(s0.pos, i);
    const double ri = s0.radius[i];
    Vec3 F{0, 0, 0}, T{0, 0, 0};
    for (std::size_t j = 0; j < s0.n; ++j) {
      if (j == i)
        continue;
      const Vec3 d = at(s0.pos, j) - xi;
      const double l = std::sqrt(dot(d, d));
      const double rj = s0.radius[j];
      if (l >= ri + rj)
        continue;
      ++pairContacts;
      const Vec3 n = (1.0 / l) * d;
      const Lsd::Pair pp =
          setup.pairs[s0.material[i] * setup.nMaterials + s0.material[j]].of<Lsd>();
      const double etan = pp.dampFactor * std::sqrt(pp.kn * effectiveMass(s0.mass[i], s0.mass[j]));
      const LsdParams lp{pp.kn, pp.kt, etan, pp.etatFactor * etan, pp.mu};
      const double lij = leverArm(l, ri, rj), lji = leverArm(l, rj, ri);
      const Vec3 vij = relativeVelocity(at(s0.vel, i), at(s0.vel, j), at(s0.omega, i),
                                        at(s0.omega, j), lij, lji, n);
      const bool owner = s0.gid[i] < s0.gid[j];
      Vec3 hist{0, 0, 0};
      if (owner) {
        slotOf(s0, i, s0.gid[j], hist);
      } else if (slotOf(s0, j, s0.gid[i], hist)) {
        hist = -hist;
      }
      const LsdResult res = lsdContact(lp, n, ri + rj - l, vij, lij, hist, dt);
      F += res.force;
      T += res.torque;
      if (owner) { // the updated history is kept once, by the owner
        Vec3 stored{0, 0, 0};
        ASSERT_TRUE(slotOf(s1, row1.at(s0.gid[i]), s0.gid[j], stored));
        const Vec3 e = stored - res.deltaT;
        dErr = std::max(dErr, std::sqrt(dot(e, e)));
        dMax = std::max(dMax, std::sqrt(dot(res.deltaT, res.deltaT)));
        Vec3 none{0, 0, 0};
        EXPECT_FALSE(slotOf(s1, row1.at(s0.gid[j]), s0.gid[i], none)) << "history kept twice";
        // Sliding: |k_t δ_t| = μ|f_n| after the update (the Coulomb branch ran).
        const Vec3 fn = (-pp.kn * (ri + rj - l)) * n - etan * (dot(vij, n) * n);
        const double ktd = pp.kt * std::sqrt(dot(res.deltaT, res.deltaT));
        const double limit = pp.mu * std::sqrt(dot(fn, fn));
        if (std::abs(ktd - limit) <= 1e-9 * limit)
          ++sliding;
      }
    }
    for (const kernels::Wall& w : setup.walls) {
      const double dn = ri - dot(xi - w.point, w.normal);
      if (dn <= 0.0)
        continue;
      const Lsd::Pair pp =
          setup.pairs[s0.material[i] * setup.nMaterials + s0.material[i]].of<Lsd>();
      const double etan = pp.dampFactor * std::sqrt(pp.kn * s0.mass[i]);
      const LsdParams lp{pp.kn, pp.kt, etan, pp.etatFactor * etan, pp.mu};
      Vec3 hist{0, 0, 0};
      slotOf(s0, i, -2, hist);
      const LsdResult res =
          wallContact(lp, w.normal, dn, at(s0.vel, i), at(s0.omega, i), ri, hist, dt);
      F += res.force;
      T += res.torque;
    }
    const std::size_t i1 = row1.at(s0.gid[i]);
    const Vec3 ef = at(s1.force, i1) - F, et = at(s1.torque, i1) - T;
    fErr = std::max(fErr, std::sqrt(dot(ef, ef)));
    tErr = std::max(tErr, std::sqrt(dot(et, et)));
    fMax = std::max(fMax, std::sqrt(dot(F, F)));
    tMax = std::max(tMax, std::sqrt(dot(T, T)));
  }
  ASSERT_GT(pairContacts, 4 * s0.n) << "not a dense bed: the test proves little";
  EXPECT_EQ(engine->pairContacts(), pairContacts / 2);
  EXPECT_GT(sliding, 0u) << "no sliding contact: the Coulomb branch is not exercised";
  // Only the summation order differs from the reference: round-off.
  EXPECT_LE(fErr, 1e-12 * fMax);
  EXPECT_LE(tErr, 1e-12 * tMax);
  EXPECT_LE(dErr, 1e-12 * dMax);
}

TEST(ContactPairs, OneAndTwoThreadsAreBitwiseIdenticalOnADenseBed) {
  // 4,096 particles: more than the 256 below which the cpu backend runs a loop serially, and
  // more than three slabs of PairLists::kMinSlab, so that the contact pass runs slabs of one
  // colour on both threads (pair_lists.h "Slabs").
  static_assert(16 * 16 * 16 > 4 * PairLists<backend::CpuExec>::kMinSlab);
  HostState s[2];
  for (int t = 0; t < 2; ++t) {
    auto engine = makeCpuEngine(denseSetup(t + 1));
    engine->setState(denseState(16));
    for (int k = 0; k < 60; ++k)
      engine->subStep(2e-6);
    s[t] = engine->state();
  }
  expectBitwiseEqual(s[0], s[1]);
}

TEST(ContactPairs, StatesWithBothSidesOfTheHistoryContinueBitwise) {
  // Before format version 3 both particles of a contact kept its history (δ_t and −δ_t).
  // Such a state continues exactly as the one-sided state does: the owner's slot is used.
  const EngineSetup setup = denseSetup(2);
  auto engine = makeCpuEngine(setup);
  engine->setState(denseState(6));
  for (int k = 0; k < 30; ++k)
    engine->subStep(2e-6);
  const HostState oneSided = engine->state();
  HostState bothSided = oneSided;
  const auto row = rowByGid(oneSided);
  std::vector<int> used(oneSided.n, 0);
  for (std::size_t i = 0; i < oneSided.n; ++i)
    for (int k = 0; k < kSlots && oneSided.histKey[i * kSlots + k] != -1; ++k)
      used[i] = k + 1;
  std::size_t mirrored = 0;
  for (std::size_t i = 0; i < oneSided.n; ++i) {
    for (int k = 0; k < used[i]; ++k) {
      const std::size_t q = i * kSlots + static_cast<std::size_t>(k);
      const std::int64_t key = oneSided.histKey[q];
      if (key < 0)
        continue; // a wall
      const std::size_t j = row.at(key);
      ASSERT_LT(used[j], kSlots);
      const std::size_t qj = j * kSlots + static_cast<std::size_t>(used[j]++);
      bothSided.histKey[qj] = oneSided.gid[i];
      for (int c = 0; c < 3; ++c)
        bothSided.histDisp[3 * qj + c] = -oneSided.histDisp[3 * q + c];
      ++bothSided.contacts[j]; // format ≤ 2: contact_count counted both sides' contacts
      ++mirrored;
    }
  }
  ASSERT_GT(mirrored, oneSided.n) << "too few contacts with history: the test proves little";
  HostState out[2];
  for (int v = 0; v < 2; ++v) {
    auto e = makeCpuEngine(setup);
    e->setState(v == 0 ? oneSided : bothSided);
    for (int k = 0; k < 30; ++k)
      e->subStep(2e-6);
    out[v] = e->state();
  }
  expectBitwiseEqual(out[0], out[1]);
}

// The tangential history lives with its candidate between neighbour builds and in the particles'
// slots across a re-sort (contacts.h: flushHistory, loadHistory). Stacks of two beads on the
// floor under gravity, the top one pushed sideways in sticking contact (μ = 10), each particle
// receiving at most two terms (so the summation order cannot change a bit), with a skin so small
// that the lists are rebuilt every few sub-steps, must give the bits of the same run whose lists
// are never rebuilt; a lost or misplaced history would reset the tangential spring.
TEST(ContactPairs, HistoryFollowsItsPairThroughNeighbourRebuilds) {
  constexpr int kStacks = 8;
  const double r = 0.5 * kDiameter, rho = 2500.0, g = 9.81, kn = 200.0;
  const double m = rho * 4.0 / 3.0 * kPi * r * r * r;
  HostState st;
  st.n = 2 * kStacks;
  st.historySlots = kSlots;
  st.neighbourSlots = 32;
  for (int k = 0; k < kStacks; ++k) {
    const double a = 0.7 * k;              // the top bead's direction in the horizontal plane
    const double x0 = 4.0 * kDiameter * k; // stacks far apart
    // Bottom on the floor, top on the bottom, at their static overlaps (2mg/k_n, mg/k_n).
    const double zb = r - 2.0 * m * g / kn;
    const double zt = zb + 2.0 * r - m * g / kn;
    for (int side = 0; side < 2; ++side) {
      const double z = side == 0 ? zb : zt;
      for (const double q : {x0, 0.0, z})
        st.pos.push_back(q);
      const double v = side == 0 ? 0.0 : 0.02;
      for (const double q : {v * std::cos(a), v * std::sin(a), 0.0})
        st.vel.push_back(q);
      for (int d = 0; d < 3; ++d)
        st.omega.push_back(0.0);
      st.radius.push_back(r);
      st.density.push_back(rho);
      st.mass.push_back(m);
      st.temperature.push_back(300.0);
      st.material.push_back(0);
      st.gid.push_back(2 * k + (k % 2 == 0 ? side : 1 - side)); // either bead the owner
    }
  }
  st.xref = st.pos;
  fillDefaults(st);
  EngineSetup setup = denseSetup(1);
  setup.pairs = {lsdRow(kn, 0.5 * kn, 0.3, 0.5, 10.0)}; // μ = 10: the contacts stick
  setup.nMaterials = 1;
  setup.gravity = Vec3{0.0, 0.0, -g};
  HostState out[2];
  std::uint64_t rebuilds[2];
  for (int v = 0; v < 2; ++v) {
    setup.skin = v == 0 ? 0.1 * kDiameter : 1e-4 * kDiameter;
    auto e = makeCpuEngine(setup);
    e->setState(st);
    for (int k = 0; k < 300; ++k)
      e->subStep(2e-6);
    rebuilds[v] = e->times().rebuilds;
    out[v] = e->state();
  }
  ASSERT_LE(rebuilds[0], 1u);
  ASSERT_GE(rebuilds[1], 50u) << "the lists were not rebuilt often: the test proves little";
  // Particle by particle (the order of the rows follows the rebuilds).
  const auto row = rowByGid(out[1]);
  std::size_t withHistory = 0;
  double largest = 0.0;
  for (std::size_t i = 0; i < out[0].n; ++i) {
    const std::size_t i1 = row.at(out[0].gid[i]);
    using Field = std::vector<double> HostState::*;
    for (const Field f : {&HostState::pos, &HostState::vel, &HostState::omega, &HostState::force,
                          &HostState::torque})
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ((out[0].*f)[3 * i + c], (out[1].*f)[3 * i1 + c]) << "gid " << out[0].gid[i];
    for (std::int64_t key : {std::int64_t{-2}, out[0].gid[i] ^ 1}) { // the floor, the partner
      Vec3 d0{0, 0, 0}, d1{0, 0, 0};
      const bool has0 = slotOf(out[0], i, key, d0), has1 = slotOf(out[1], i1, key, d1);
      EXPECT_EQ(has0, has1) << "gid " << out[0].gid[i] << ", key " << key;
      EXPECT_EQ(d0.x, d1.x);
      EXPECT_EQ(d0.y, d1.y);
      EXPECT_EQ(d0.z, d1.z);
      if (key >= 0 && has1) {
        ++withHistory;
        largest = std::max(largest, kernels::norm(d1));
      }
    }
  }
  // Every stack kept its contact and a tangential displacement (the damped spring oscillates;
  // 4.3e-8 m at the end).
  EXPECT_EQ(withHistory, static_cast<std::size_t>(kStacks));
  EXPECT_GT(largest, 1e-8);
}

// Handing out the state (which writes the history into the slots) and restarting from it, at
// any sub-step and with neighbour rebuilds in between, leave the run bitwise unchanged.
TEST(ContactPairs, StatesAndRestartsLeaveTheRunUnchanged) {
  EngineSetup setup = denseSetup(2);
  setup.skin = 2e-2 * kDiameter; // a rebuild every ten sub-steps or so
  HostState out[2];
  std::uint64_t rebuilds = 0;
  for (int v = 0; v < 2; ++v) {
    auto e = makeCpuEngine(setup);
    e->setState(denseState(8));
    for (int k = 0; k < 60; ++k) {
      e->subStep(2e-6);
      if (v == 1) {
        const HostState s = e->state();
        if (k % 9 == 4) { // a fresh engine from the state
          rebuilds += e->times().rebuilds;
          e = makeCpuEngine(setup);
          e->setState(s);
        }
      }
    }
    if (v == 1)
      rebuilds += e->times().rebuilds;
    out[v] = e->state();
  }
  ASSERT_GE(rebuilds, 5u) << "no rebuilds between the states: the test proves little";
  expectBitwiseEqual(out[0], out[1]);
}

// Wall candidates are taken from the last neighbour build (contacts.h, buildWallCandidates):
// particles flying at walls from every side, from gaps just below and just above skin/2, with
// stale neighbour lists from a state file, must feel each wall in exactly the sub-steps in which
// a brute-force check over every wall finds an overlap.
TEST(ContactPairs, WallCandidatesMissNoContact) {
  EngineSetup s = denseSetup(1);
  const double L = 10.0 * kDiameter;
  s.walls = {kernels::planeWall(Vec3{0, 0, 0}, Vec3{1, 0, 0}),
             kernels::planeWall(Vec3{L, 0, 0}, Vec3{-1, 0, 0}),
             kernels::planeWall(Vec3{0, 0, 0}, Vec3{0, 1, 0}),
             kernels::planeWall(Vec3{0, L, 0}, Vec3{0, -1, 0}),
             kernels::planeWall(Vec3{0, 0, 0}, Vec3{0, 0, 1}),
             kernels::planeWall(Vec3{0, 0, L}, Vec3{0, 0, -1})};
  HostState st;
  st.historySlots = kSlots;
  st.neighbourSlots = 32;
  const double r = 0.5 * kDiameter;
  const double halfSkin = 0.5 * s.skin;
  // One particle per wall and per starting gap, spread along the wall, heading at it at 0.3 m/s.
  int k = 0;
  for (int w = 0; w < 6; ++w) {
    for (const double gap : {0.3 * halfSkin, 0.54 * halfSkin, 0.9 * halfSkin, 0.999 * halfSkin,
                             1.001 * halfSkin, 1.5 * halfSkin, 3.0 * halfSkin}) {
      const int axis = w / 2;
      const bool low = w % 2 == 0;
      double x[3] = {0.5 * L, 0.5 * L, 0.5 * L};
      x[(axis + 1) % 3] = (1.5 + 1.2 * (k % 7)) * kDiameter; // apart from each other
      x[(axis + 2) % 3] = (1.5 + 1.1 * (k / 7)) * kDiameter;
      x[axis] = low ? r + gap : L - r - gap;
      double v[3] = {0.0, 0.0, 0.0};
      v[axis] = low ? -0.3 : 0.3;
      for (int d = 0; d < 3; ++d) {
        st.pos.push_back(x[d]);
        st.vel.push_back(v[d]);
        st.omega.push_back(0.0);
      }
      st.radius.push_back(r);
      st.density.push_back(2500.0);
      st.mass.push_back(2500.0 * 4.0 / 3.0 * kPi * r * r * r);
      st.temperature.push_back(300.0);
      st.material.push_back(0);
      st.gid.push_back(k);
      ++k;
    }
  }
  st.n = static_cast<std::size_t>(k);
  fillDefaults(st);
  // xref half a skin behind the positions: as if the particles had moved since the last build.
  st.xref = st.pos;
  for (std::size_t i = 0; i < st.n; ++i)
    for (int d = 0; d < 3; ++d)
      st.xref[3 * i + d] -= 0.45 * halfSkin *
                            (st.vel[3 * i + d] > 0   ? 1
                             : st.vel[3 * i + d] < 0 ? -1
                                                     : 0);
  checkShapes(st, "wall approach");

  for (const bool staleList : {false, true}) {
    auto engine = makeCpuEngine(s);
    HostState start = st;
    start.listValid = staleList ? 1 : 0;
    if (staleList) { // every list empty (no particle within reach of another): valid as such
      start.nbCount.assign(start.n, 0);
    }
    engine->setState(start);
    const double dt = 1e-6;
    std::size_t touched = 0;
    for (int step = 0; step < 400; ++step) {
      const HostState before = engine->state();
      std::size_t expected = 0;
      for (std::size_t i = 0; i < before.n; ++i)
        for (const auto& w : s.walls)
          expected += before.radius[i] - kernels::wallClearance(w, at(before.pos, i)) > 0.0 ? 1 : 0;
      engine->subStep(dt);
      ASSERT_EQ(engine->wallContacts(), expected) << "sub-step " << step << " stale=" << staleList;
      touched += expected;
      // The wall force is kept only in rows with wall contacts (contacts.h): every other row
      // reads zero, also after the particle left the wall and after rebuilds re-sorted the rows.
      const HostState after = engine->state();
      for (std::size_t i = 0; i < after.n; ++i) {
        const Vec3 fw = at(after.fwall, i);
        if (after.wallContacts[i] == 0) {
          ASSERT_TRUE(fw.x == 0.0 && fw.y == 0.0 && fw.z == 0.0)
              << "particle " << after.gid[i] << " without wall contact keeps a wall force, "
              << "sub-step " << step;
        } else {
          ASSERT_GT(kernels::norm(fw), 0.0) << "particle " << after.gid[i] << ", sub-step " << step;
        }
      }
    }
    EXPECT_GT(touched, 0u);                  // the particles did reach the walls
    EXPECT_GE(engine->times().rebuilds, 2u); // rows were re-sorted while particles touched walls
  }
}

namespace {

/// A sphere of radius R (material 0) with n small spheres (material 1, radius a) around it at
/// random directions, the first `touching` pressed onto it, the others within the skin; the big
/// sphere owns every pair (smallest gid): a long half list, mostly not in contact.
HostState crowdedState(int n, int touching, double R, double a, double skin) {
  HostState s;
  s.n = static_cast<std::size_t>(n + 1);
  s.historySlots = 32;
  s.neighbourSlots = 256;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto add = [&](Vec3 x, double r, int material, std::int64_t gid) {
    s.pos.insert(s.pos.end(), {x.x, x.y, x.z});
    for (int d = 0; d < 3; ++d) {
      s.vel.push_back(0.05 * u(rng));
      s.omega.push_back(50.0 * u(rng));
    }
    s.radius.push_back(r);
    s.density.push_back(2500.0);
    s.mass.push_back(2500.0 * 4.0 / 3.0 * kPi * r * r * r);
    s.temperature.push_back(300.0);
    s.material.push_back(material);
    s.gid.push_back(gid);
  };
  const Vec3 c{0.02, 0.02, 0.02};
  add(c, R, 0, 0);
  for (int k = 0; k < n; ++k) {
    Vec3 dir{u(rng), u(rng), u(rng)};
    dir = (1.0 / kernels::norm(dir)) * dir;
    add(c + (k < touching ? R + 0.97 * a : R + a + 0.3 * skin) * dir, a, 1, k + 1);
  }
  s.xref = s.pos;
  fillDefaults(s);
  checkShapes(s, "crowdedState");
  return s;
}

} // namespace

// The cpu backend evaluates two consecutive owned pairs in contact at once, in the two lanes of
// Double2, and adds the partners' shares slab colour by colour; cuda-sim runs the same module
// one pair at a time and gathers the shares in a second pass in the same order (the CUDA path).
// Same bits. The 4,096-particle bed has several slabs of each colour.
TEST(ContactPairs, TwoLanePairsGiveTheOnePairAtATimeBits) {
  struct Deck {
    HostState state;
    EngineSetup setup;
  };
  std::vector<Deck> decks;
  decks.push_back({denseState(16), denseSetup(2)});
  // One particle owning 192 candidates, 20 in contact: a wide neighbour list and more slots.
  EngineSetup crowded = denseSetup(2);
  crowded.walls.clear();
  crowded.maxRadius = 4e-3;
  crowded.neighbourSlots = 256;
  crowded.historySlots = 32;
  decks.push_back({crowdedState(192, 20, 4e-3, 0.25e-3, crowded.skin), crowded});
  for (Deck& d : decks) {
    auto cpu = makeCpuEngine(d.setup);
    auto sim = makeCudaSimEngine(d.setup);
    cpu->setState(d.state);
    sim->setState(d.state);
    for (int k = 0; k < 40; ++k) {
      cpu->subStep(2e-6);
      sim->subStep(2e-6);
    }
    const HostState a = cpu->state();
    const HostState b = sim->state();
    expectBitwiseEqual(a, b);
    EXPECT_GT(*std::max_element(a.contacts.begin(), a.contacts.end()), 0);
  }
}
