#pragma once
/// @file
/// The chemistry part of `coredem-bench thermochem`: the reaction-rate kernels (CLG R1/R2,
/// R4/R5, a generic Arrhenius reaction) and the particle mass/species update, run as one
/// parallel loop over the particles each, the way a DEM sub-step evaluates them (one particle
/// per index, the cell's gas state read by the particle's PCM cell). Written once for the cpu
/// loop (thermochem.cpp, OpenMP) and the CUDA kernels (thermochem.cu).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "coredem/dem/kernels/clg_char_gasification.h"
#include "coredem/dem/kernels/clg_oc_reduction.h"
#include "coredem/dem/kernels/nasa7.h"
#include "coredem/dem/kernels/reaction_generic.h"
#include "coredem/dem/kernels/species_particle.h"

#if defined(__CUDACC__)
#define COREDEM_BENCH_HD __host__ __device__
#else
#define COREDEM_BENCH_HD
#endif

namespace coredem::bench::thermochem {

/// Solid species per particle in the benchmark (char: C, ash, −; OC: Fe2O3, Fe3O4, Al2O3).
constexpr int kSolids = 3;
constexpr int kGas = coredem::dem::kernels::kGasSpeciesCount;

/// The chemistry stages, in report order.
enum ChemStage : int { kCharR1R2 = 0, kOcR4R5, kGeneric, kMassSpecies, kChemStageCount };
inline constexpr const char* kChemStageNames[kChemStageCount] = {
    "reaction_rates_clg_r1_r2", "reaction_rates_clg_r4_r5", "reaction_rates_generic",
    "mass_species_update"};

/// Host input: the particles of the engine (temperatures, masses, PCM cells) and the cells'
/// gas composition.
struct ChemInput {
  std::size_t n = 0;
  std::vector<double> T, mass, Y; ///< N, N, N*kSolids
  std::vector<std::int32_t> cell; ///< N, PCM cell of each particle
  std::vector<double> pBar, conc; ///< nCells*kGas: partial pressures (bar), concentrations (mol/m³)
  double dt = 1e-6;               ///< sub-step (s)
  double density = 2500.0;        ///< particle density for the shrinking diameter (kg/m³)
};

/// Device (or host) pointers of one run.
struct ChemArrays {
  std::size_t n;
  const double* T;
  const double* mass0;
  const std::int32_t* cell;
  const double* pBar;
  const double* conc;
  double* m;             ///< N (updated by kMassSpecies)
  double* Y;             ///< N*kSolids (updated by kMassSpecies)
  double* mdot;          ///< N*kSolids, kg/s
  double* mdotGas;       ///< N*kGas, kg/s
  double* q;             ///< N, W
  double* d;             ///< N, m
  std::int32_t* removed; ///< N
  double dt;
  double density;
};

/// C + CO2 → 2 CO as a generic heterogeneous reaction (Arrhenius, first order in CO2).
inline coredem::dem::kernels::HeterogeneousReaction genericReaction() {
  using namespace coredem::dem::kernels;
  HeterogeneousReaction r;
  r.n = 3;
  r.phase[0] = ReactionPhase::Solid;
  r.index[0] = 0;
  r.nu[0] = -1.0;
  r.molarMass[0] = 12.011e-3;
  r.phase[1] = ReactionPhase::Gas;
  r.index[1] = 1;
  r.nu[1] = -1.0;
  r.molarMass[1] = 44.0095e-3;
  r.phase[2] = ReactionPhase::Gas;
  r.index[2] = 0;
  r.nu[2] = 2.0;
  r.molarMass[2] = 28.0101e-3;
  r.law = RateLaw::Arrhenius;
  r.A = 1.0e3;
  r.beta = 0.0;
  r.E = 1.5e5;
  r.orderTerm = 1;
  r.order = 1.0;
  r.dH = 1.72e5;
  return r;
}

/// The body of one stage for particle i.
COREDEM_BENCH_HD inline void chemBody(int stage, const ChemArrays& a,
                                      const coredem::dem::kernels::HeterogeneousReaction& gen,
                                      std::size_t i) {
  using namespace coredem::dem::kernels;
  const int c = a.cell[i];
  double* y = a.Y + kSolids * i;
  double* md = a.mdot + kSolids * i;
  double* mg = a.mdotGas + kGas * i;
  switch (stage) {
  case kCharR1R2: {
    const CharGasificationParams p;
    const double mC = a.m[i] * y[0];
    const CharGasificationRates r = charGasification(p, a.T[i], a.pBar + kGas * c, mC, a.mass0[i]);
    const double s = charStepLimiter(r, mC, a.dt);
    md[0] = s * r.mdotC;
    md[1] = 0.0;
    md[2] = 0.0;
    for (int k = 0; k < kGas; ++k)
      mg[k] = s * r.mdotGas[k];
    a.q[i] = s * r.heat;
    break;
  }
  case kOcR4R5: {
    const OcReductionParams p;
    const double* cc = a.conc + kGas * c;
    const OcReductionRates r =
        ocReduction(p, a.T[i], a.m[i], y, cc[idx(GasSpecies::CO)], cc[idx(GasSpecies::H2)]);
    const double s = ocStepLimiter(r, a.m[i], y, a.dt);
    for (int k = 0; k < kSolids; ++k)
      md[k] = s * r.mdotSolid[k];
    for (int k = 0; k < kGas; ++k)
      mg[k] = s * r.mdotGas[k];
    a.q[i] = s * r.heat;
    break;
  }
  case kGeneric: {
    double solidMass[kSolids];
    for (int k = 0; k < kSolids; ++k)
      solidMass[k] = a.m[i] * y[k];
    const double w = heterogeneousExtentRate(gen, a.T[i], a.conc + kGas * c, solidMass, a.dt);
    double sr[kSolids] = {0.0, 0.0, 0.0};
    double gr[kGas] = {0.0, 0.0, 0.0, 0.0, 0.0};
    addHeterogeneousSources(gen, w, sr, gr);
    for (int k = 0; k < kSolids; ++k)
      md[k] = sr[k];
    for (int k = 0; k < kGas; ++k)
      mg[k] = gr[k];
    a.q[i] = heterogeneousHeat(gen, w);
    break;
  }
  default: { // kMassSpecies: Eq. 31 explicit Euler, shrinking diameter (Eq. 32), removal test
    double m = a.m[i];
    updateParticleSpecies(m, y, md, kSolids, a.dt);
    a.m[i] = m;
    const double d = shrinkingDiameter(m, a.density);
    a.d[i] = d;
    a.removed[i] = particleShouldBeRemoved(d, shrinkingDiameter(a.mass0[i], a.density)) ? 1 : 0;
    break;
  }
  }
}

/// Seconds spent in each stage over `reps` repetitions (each repetition runs every stage once,
/// in order, on the same arrays).
struct ChemTimes {
  double seconds[kChemStageCount] = {};
  int reps = 0;
};

/// CUDA run of the same stages (thermochem.cu; only in builds with COREDEM_CUDA_ENABLED).
/// Throws std::runtime_error when no device is usable.
ChemTimes runChemistryCuda(const ChemInput& in, int reps);

} // namespace coredem::bench::thermochem
