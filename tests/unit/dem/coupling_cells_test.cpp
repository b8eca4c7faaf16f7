// The sort of the particles by coupling cell (coupling_cells.h): on the cpu backend a sort in which
// few particles changed cell merges them into the last order instead of sorting again. Whatever
// changed, perm and the ranges of the occupied cells must be those of a full sort (the stable
// order by cell, then index), which the drag, heat and chemistry sums rely on for their bits.
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "backend/cpu/cpu_exec.h"
#include "coupling_cells.h"

using namespace coredem::dem;
using backend::CpuExec;

namespace {

/// Sorts `pc` in `cells` (which may keep its last sort) and in a fresh CouplingCells (a full
/// sort); expects the same perm and the same range of every occupied cell.
void expectSameAsFullSort(CpuExec& exec, CouplingCells<CpuExec>& cells,
                          const std::vector<std::uint32_t>& pc, std::size_t nCells, int round) {
  const std::size_t n = pc.size();
  std::copy(pc.begin(), pc.end(), cells.pcell());
  cells.sort(exec, n);
  CouplingCells<CpuExec> fresh;
  fresh.setup(nCells);
  fresh.reserveParticles(n);
  std::copy(pc.begin(), pc.end(), fresh.pcell());
  fresh.sort(exec, n);
  for (std::size_t k = 0; k < n; ++k)
    ASSERT_EQ(cells.perm()[k], fresh.perm()[k]) << "round " << round << ", position " << k;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t c = pc[i];
    ASSERT_EQ(cells.cStart()[c], fresh.cStart()[c]) << "round " << round << ", cell " << c;
    ASSERT_EQ(cells.cEnd()[c], fresh.cEnd()[c]) << "round " << round << ", cell " << c;
  }
}

} // namespace

TEST(CouplingCellsSort, FewOrManyChangesGiveTheFullSortsOrder) {
  CpuExec exec;
  exec.threads = 2;
  const std::size_t nCells = 97, n = 20000;
  std::mt19937_64 rng(11);
  std::vector<std::uint32_t> pc(n);
  for (auto& c : pc)
    c = static_cast<std::uint32_t>(rng() % (nCells + 1)); // nCells: outside the grid
  CouplingCells<CpuExec> cells;
  cells.setup(nCells);
  cells.reserveParticles(n);
  // Rounds with no change, one change, a few (merged), many (sorted again), into and out of
  // the sentinel "outside" cell, and a permutation of the particles (as a neighbour rebuild
  // reorders them: few values change at each index if neighbours share cells, or all).
  const std::size_t changes[] = {0, 1, 0, 7, 50, 600, 1249, 1250, 5000, 3, 0, 20000, 2};
  int round = 0;
  for (const std::size_t m : changes) {
    for (std::size_t k = 0; k < m; ++k)
      pc[rng() % n] = static_cast<std::uint32_t>(rng() % (nCells + 1));
    expectSameAsFullSort(exec, cells, pc, nCells, round++);
  }
  std::shuffle(pc.begin(), pc.end(), rng);
  expectSameAsFullSort(exec, cells, pc, nCells, round++);
  // Swapping two particles of the same cell changes nothing in pcell: perm stays valid.
  for (std::size_t a = 0; a < n; ++a) {
    for (std::size_t b = a + 1; b < n; ++b) {
      if (pc[a] == pc[b] && pc[a] != pc[a + 1]) {
        std::swap(pc[a + 1], pc[b]);
        break;
      }
    }
    if (a > 100)
      break;
  }
  expectSameAsFullSort(exec, cells, pc, nCells, round++);
  // Fewer particles (removal): the next sort starts again.
  pc.resize(n - 10);
  cells.reserveParticles(pc.size());
  expectSameAsFullSort(exec, cells, pc, nCells, round++);
  pc[5] = static_cast<std::uint32_t>((pc[5] + 1) % (nCells + 1));
  expectSameAsFullSort(exec, cells, pc, nCells, round++);
}
