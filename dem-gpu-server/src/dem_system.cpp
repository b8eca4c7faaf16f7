// DemSystem: the engine built from a checked config (config_setup.h), Δt_DEM, sub-cycling,
// state I/O.
// Everything that runs per particle per step is in the backend engine (engine_impl.h).
#include "coredem/dem/dem_system.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <unordered_map>

#include "backend/sync_counters.h"
#include "chemistry_config.h"
#include "config_setup.h"
#include "coredem/common/check.h"
#include "coredem/common/log.h"
#include "coredem/common/version.h"
#include "coredem/dem/kernels/damping.h"
#include "coredem/dem/kernels/pressure_gradient.h"
#include "coredem/dem/models.h"
#include "coredem/dem/time_handler.h"
#include "coredem/dem/triangle_mesh.h"
#include "engine.h"
#include "state_io.h"

namespace coredem::dem {

using namespace cfg;

BackendKind parseBackend(const std::string& name) {
  if (name == "cpu")
    return BackendKind::Cpu;
  if (name == "cuda")
    return BackendKind::Cuda;
  if (name == "auto")
    return BackendKind::Auto;
  if (name == "cuda-sim")
    return BackendKind::CudaSim;
  throw UserError("unknown DEM backend '" + name + "'; use cpu, cuda or auto");
}

std::string backendName(BackendKind kind) {
  switch (kind) {
  case BackendKind::Cpu:
    return "cpu";
  case BackendKind::Cuda:
    return "cuda";
  case BackendKind::Auto:
    return "auto";
  case BackendKind::CudaSim:
    return "cuda-sim";
  }
  return "?";
}

bool cudaBackendBuilt() {
#if defined(COREDEM_CUDA_ENABLED)
  return true;
#else
  return false;
#endif
}

CudaProbe probeCuda() {
#if defined(COREDEM_CUDA_ENABLED)
  return cudaProbe();
#else
  CudaProbe p;
  p.note = "this build has no CUDA backend (configure with -DCOREDEM_CUDA=ON)";
  return p;
#endif
}

int cudaDeviceCount() {
  return probeCuda().devices;
}

BackendSyncCounts backendSyncCounts() {
  const backend::SyncCounters& c = backend::syncCounters();
  return {c.hostRoundTrips.load(), c.deviceSyncs.load(), c.launches.load()};
}

struct DemSystem::Impl {
  DemConfig config;
  EngineSetup setup;
  std::unique_ptr<Engine> engine;
  TimeHandler time;
  std::uint64_t step = 0;
  double dtMax = 0;
  std::string hash;
  CellSources sources;
  std::size_t nParticles = 0;
  const std::atomic<bool>* interrupt = nullptr; ///< setInterruptFlag
  BackendKind kind = BackendKind::Cpu;
  bool warnedUnassignedSplit = false; ///< the warning about heat split to no particle was logged
  std::unique_ptr<Engine> makeEngine() const {
#if defined(COREDEM_CUDA_ENABLED)
    if (kind == BackendKind::Cuda)
      return makeCudaEngine(setup);
#endif
    if (kind == BackendKind::CudaSim)
      return makeCudaSimEngine(setup);
    return makeCpuEngine(setup);
  }
  std::shared_ptr<coredem::Logger> log = coredem::logger("dem.system");
  /// The particles of state `st` (read from `path`) as this system's: checks, engine, Δt_DEM,max.
  void adoptState(const std::string& path, HostState& st);
};

DemSystem::DemSystem(const DemConfig& config, BackendKind backend, int threads)
    : _impl(std::make_unique<Impl>()) {
  Impl& m = *_impl;
  validate(config);
  COREDEM_CHECK(threads >= 0, "threads = {} must be >= 0 (0 = OpenMP default)", threads);
  m.config = config;
  m.interrupt = config.interrupt;
  m.hash = hashConfig(config);

  // Particles.
  HostState st;
  const int ns = static_cast<int>(config.solidSpecies.size());
  st.nSpecies = ns;
  st.historySlots = config.neighbour.historySlots;
  st.neighbourSlots = config.neighbour.initialNeighbourSlots;
  double rmax = 0;
  std::vector<double> minMass(config.materials.size(), std::numeric_limits<double>::infinity());
  std::vector<double> minRadius(config.materials.size(), 1.0); // of the lightest (dtDemMax)
  std::int64_t nextId = 0;
  for (const ParticleSet& s : config.particleSets) {
    const std::vector<double> p = placeParticles(s, config.interrupt);
    const std::size_t n = p.size() / 3;
    Rng rng{s.seed ^ 0x5bd1e995a5a5a5a5ull};
    const double r = 0.5 * s.diameter;
    const double mass = s.density * kernels::sphereVolume(r);
    rmax = std::max(rmax, r);
    if (mass < minMass[s.material]) {
      minMass[s.material] = mass;
      minRadius[s.material] = r;
    }
    for (std::size_t k = 0; k < n; ++k) {
      for (int d = 0; d < 3; ++d) {
        st.pos.push_back(p[3 * k + d]);
        double v = s.velocity[d];
        if (!s.velocities.empty())
          v = s.velocities[3 * k + d];
        if (s.velocityJitter > 0)
          v += s.velocityJitter * (2.0 * rng.uniform() - 1.0);
        st.vel.push_back(v);
        st.omega.push_back(s.angularVelocities.empty() ? 0.0 : s.angularVelocities[3 * k + d]);
      }
      st.radius.push_back(r);
      st.mass.push_back(mass);
      st.density.push_back(s.density);
      st.temperature.push_back(s.temperature);
      for (int q = 0; q < ns; ++q)
        st.species.push_back(s.composition.empty() ? (q == 0 ? 1.0 : 0.0) : s.composition[q]);
      st.material.push_back(s.material);
      st.gid.push_back(nextId++);
    }
  }
  const std::size_t n = st.gid.size();
  COREDEM_CHECK(n < (1ull << 31), "{} particles: at most 2^31-1 are supported", n);
  st.n = n;
  st.xref = st.pos;
  st.listValid = 0;
  initChemistryReferences(config, st); // d_p0, initial C / Fe2O3-equivalent masses
  // Every other field (forces, contact counts, history, neighbour lists, ...) starts from its
  // particle-schema default (zero; empty history slots −1).
  fillDefaults(st);
  m.nParticles = n;

  const std::size_t nm = config.materials.size();
  m.dtMax = coredem::dem::dtDemMax(config, minMass, minRadius);

  // Engine set-up.
  EngineSetup& es = m.setup;
  es.nMaterials = static_cast<int>(nm);
  setUpContacts(config, es); // the contact law and its rows of the material pairs
  for (const Wall& w : config.walls)
    es.walls.push_back(kernelWall(w));
  es.triangles = kernelTriangles(config.meshes);
  es.gravity = {config.gravity[0], config.gravity[1], config.gravity[2]};
  es.nCells = config.grid.cellCount();
  es.coupled = es.nCells > 0;
  if (es.coupled) {
    const CouplingGrid& g = config.grid;
    es.grid = kernels::GridParams{{g.origin[0], g.origin[1], g.origin[2]},
                                  {1.0 / g.spacing[0], 1.0 / g.spacing[1], 1.0 / g.spacing[2]},
                                  g.counts[0],
                                  g.counts[1],
                                  g.counts[2]};
    es.cellVolume = g.spacing[0] * g.spacing[1] * g.spacing[2];
  }
  es.nGasSpecies = static_cast<int>(config.gasSpecies.size());
  es.drag.law = config.drag;
  es.drag.laws = config.dragLaws;
  es.drag.epsMin = config.epsMinDrag;
  es.maxRadius = rmax;
  es.skin = config.neighbour.skinFactor * 2.0 * rmax;
  es.historySlots = config.neighbour.historySlots;
  es.neighbourSlots = config.neighbour.initialNeighbourSlots;
  es.threads = threads;
  es.frozen = config.frozenMotion;
  setUpHeat(config, rmax, es); // heat transfer (heat.h), thermal walls

  es.chem = makeChemistrySetup(config); // chemistry (chemistry.h); validates the options

  BackendKind kind = backend;
  if (kind == BackendKind::Auto) {
    const CudaProbe cuda = probeCuda();
    kind = cuda.devices > 0 ? BackendKind::Cuda : BackendKind::Cpu;
    if (!cuda.error.empty()) // a broken GPU setup is not "no GPU": say so loudly
      m.log->warn("backend auto: running on the cpu because the CUDA backend cannot run: {}",
                  cuda.error);
    else if (cuda.devices == 0)
      m.log->info("backend auto: running on the cpu ({})", cuda.note);
  }
  if (kind == BackendKind::Cuda) {
    COREDEM_CHECK(cudaBackendBuilt(),
                  "backend 'cuda' requested but this build has no CUDA backend; "
                  "rebuild with -DCOREDEM_CUDA=ON or use --backend cpu");
    const CudaProbe cuda = probeCuda();
    COREDEM_CHECK(cuda.error.empty(), "backend 'cuda' requested but {}", cuda.error);
    COREDEM_CHECK(cuda.devices > 0,
                  "backend 'cuda' requested but there is no CUDA device: {}; use --backend cpu "
                  "(or auto)",
                  cuda.note);
  }
  m.kind = kind;
  m.engine = m.makeEngine();
  m.engine->setState(st);
  m.log->debug("DemSystem: {} particles, backend {}, dt_dem_max {:.6g} s, config {}", n,
               m.engine->name(), m.dtMax, m.hash);
}

DemSystem::~DemSystem() = default;

double DemSystem::dtDemMax() const {
  return _impl->dtMax;
}

void DemSystem::setGasFields(const GasFieldsView& gas) {
  Impl& m = *_impl;
  COREDEM_CHECK(m.setup.coupled,
                "setGasFields: no coupling grid is configured (DemConfig.grid counts are 0)");
  const std::size_t nc = m.setup.nCells;
  const std::size_t ns = m.config.gasSpecies.size();
  auto check = [&](std::span<const double> s, std::size_t want, const char* name, bool optional,
                   bool positive) -> std::vector<double> {
    if (s.empty() && optional)
      return {};
    COREDEM_CHECK(s.size() == want, "setGasFields: {} has {} values, expected {} ({} cells)", name,
                  s.size(), want, nc);
    for (std::size_t k = 0; k < s.size(); ++k) {
      COREDEM_CHECK(std::isfinite(s[k]), "setGasFields: {}[{}] is not finite", name, k);
      COREDEM_CHECK(!positive || s[k] > 0, "setGasFields: {}[{}] = {} must be > 0", name, k, s[k]);
    }
    return std::vector<double>(s.begin(), s.end());
  };
  GasArrays g;
  g.ug = check(gas.ug, 3 * nc, "u_g", false, false);
  g.gradP = check(gas.gradP, 3 * nc, "grad_p", false, false);
  g.rhoG = check(gas.rhoG, nc, "rho_g", false, true);
  g.muG = check(gas.muG, nc, "mu_g", false, true);
  g.Tg = check(gas.Tg, nc, "T_g", true, true);
  g.kappaG = check(gas.kappaG, nc, "kappa_g", true, true);
  g.cpG = check(gas.cpG, nc, "cp_g", true, true);
  g.Yg = check(gas.Yg, nc * ns, "Y_g", true, false);
  g.fluidFraction = check(gas.fluidFraction, nc, "fluid_fraction", true, false);
  g.heatToParticles = check(gas.heatToParticles, nc, "Q_split", true, false);
  for (std::size_t k = 0; k < g.fluidFraction.size(); ++k) {
    COREDEM_CHECK(g.fluidFraction[k] >= 0.0 && g.fluidFraction[k] <= 1.0,
                  "setGasFields: fluid_fraction[{}] = {} must lie in [0, 1]", k,
                  g.fluidFraction[k]);
  }
  m.engine->setGas(g);
}

const CellSources& DemSystem::advance(double dtCfd, int nSub) {
  Impl& m = *_impl;
  COREDEM_CHECK(dtCfd > 0 && std::isfinite(dtCfd), "advance: dtCfd = {} must be > 0 and finite",
                dtCfd);
  COREDEM_CHECK(nSub >= 1, "advance: nSub = {} must be >= 1", nSub);
  const double dt = dtCfd / nSub;
  COREDEM_CHECK(
      dt <= m.dtMax * (1.0 + 1e-12),
      "advance: dtCfd/nSub = {:.6g} s exceeds the stable DEM step {:.6g} s (t_col/{}); use "
      "nSub >= {} (TimeHandler::subStepsFor)",
      dt, m.dtMax, m.config.dtFactor, TimeHandler::subStepsFor(dtCfd, m.dtMax));
  m.engine->beginWindow();
  const HeatSplitBooking split = m.engine->giveHeatSplit();
  if (split.unassignedCells > 0 && !m.warnedUnassignedSplit) {
    m.warnedUnassignedSplit = true;
    m.log->warn("t = {:.6g} s: {:.6g} J of the heat split the gas sent (Q_split) fell in {} "
                "coupling cell(s) without particles, first cell {}: booked as "
                "dem.heat_split_unassigned_J, given to no particle (first occurrence only)",
                m.time.time(), split.unassigned, split.unassignedCells, split.firstUnassignedCell);
  }
  for (int s = 0; s < nSub; ++s) {
    if (m.interrupt != nullptr && m.interrupt->load(std::memory_order_relaxed)) {
      throw Interrupted(coredem::format("interrupted after {} of {} sub-steps", s, nSub));
    }
    m.engine->subStep(dt);
    m.time.add(dt);
    ++m.step;
  }
  m.engine->endWindow(dtCfd, nSub, m.sources);
  if (m.engine->takeRemovalRequest()) {
    // Particles below removalFraction·d_p0: removed at the CFD-step boundary (host compaction).
    const auto t0 = std::chrono::steady_clock::now();
    HostState st = m.engine->state();
    ChemistryTotals totals = m.engine->chemistryTotals();
    const double before = totals.removedMass();
    const std::size_t removed =
        removeSmallParticles(m.config.chemistry.removalFraction, st, totals);
    m.engine->restoreChemistryTotals(totals); // the removed mass joins the chemistry ledger
    if (removed > 0) {
      m.engine->setState(st);
      m.nParticles = st.n;
      m.log->info("t = {:.6g} s: removed {} particle(s) below {} of their initial diameter ({:.6g} "
                  "kg); {} left",
                  m.time.time(), removed, m.config.chemistry.removalFraction,
                  totals.removedMass() - before, st.n);
    }
    m.engine->times().chemistry +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return m.sources;
}

const CellSources& DemSystem::evaluateSources(double dtDem) {
  Impl& m = *_impl;
  COREDEM_CHECK(dtDem > 0 && std::isfinite(dtDem) && dtDem <= m.dtMax * (1.0 + 1e-12),
                "evaluateSources: dtDem = {:.6g} s must be > 0 and <= the stable DEM step {:.6g} s",
                dtDem, m.dtMax);
  // Everything one sub-step changes is put back afterwards: particles and contact history (the
  // host state, as a restart would), the ledgers, the stage timers. Time and step are untouched.
  const HostState saved = m.engine->state();
  const HeatTotals heat = m.engine->heatTotals();
  const ChemistryTotals chemistry = m.engine->chemistryTotals();
  const StageTimes times = m.engine->times();
  m.engine->beginWindow();
  m.engine->subStep(dtDem);
  m.engine->endWindow(dtDem, 1, m.sources);
  (void)m.engine->takeRemovalRequest(); // no removal: the state is put back
  m.engine->setState(saved);
  m.engine->restoreHeatTotals(heat);
  m.engine->restoreChemistryTotals(chemistry);
  m.engine->times() = times;
  return m.sources;
}

void DemSystem::setInterruptFlag(const std::atomic<bool>* flag) {
  _impl->interrupt = flag;
}

void DemSystem::writeState(const std::string& path, const std::string& protocolVersion) const {
  Impl& m = *_impl;
  StateMeta meta;
  meta.time = m.time.time();
  meta.timeCompensation = m.time.compensation();
  meta.step = m.step;
  meta.backend = m.engine->name();
  meta.configHash = m.hash;
  meta.softwareVersion = std::string(
      coredem::kVersion); // (not operator=(const char*): GCC 12 -Wrestrict false positive)
  meta.protocolVersion = protocolVersion.empty() ? std::string("none") : protocolVersion;
  meta.heat = m.engine->heatTotals();
  meta.hasChemistry = m.config.chemistry.active();
  meta.chemistry = m.engine->chemistryTotals();
  for (const Material& mat : m.config.materials)
    meta.materialNames.push_back(mat.name);
  writeStateFile(path, m.engine->state(), meta);
}

void DemSystem::readState(const std::string& path) {
  Impl& m = *_impl;
  HostState st;
  StateMeta meta;
  readStateFile(path, st, meta);
  COREDEM_CHECK(
      meta.configHash == m.hash,
      "state file '{}' was written with config hash {} but this system's is {}: restart with "
      "the same materials, walls, gravity, grid, species and options (a new start from another "
      "run's state with a different configuration: case.yaml initial_state)",
      path, meta.configHash, m.hash);
  m.adoptState(path, st);
  m.engine->restoreHeatTotals(meta.heat);
  if (meta.hasChemistry)
    m.engine->restoreChemistryTotals(meta.chemistry);
  m.time.restore(meta.time, meta.timeCompensation);
  m.step = meta.step;
}

namespace {

/// A new start keeps the tangential history of particle pairs (partners by global id) and
/// drops the walls' (the new configuration's walls may differ): the first wallContacts slots
/// of each particle's row, the rest moved forward.
void dropWallHistory(HostState& st) {
  const std::size_t h = static_cast<std::size_t>(st.historySlots);
  for (std::size_t i = 0; i < st.n; ++i) {
    const std::size_t w = static_cast<std::size_t>(std::max(0, st.wallContacts[i]));
    const std::size_t row = i * h;
    for (std::size_t s = 0; s < h; ++s) {
      const bool kept = s + w < h && st.histKey[row + s + w] >= 0;
      st.histKey[row + s] = kept ? st.histKey[row + s + w] : -1;
      for (std::size_t a = 0; a < 3; ++a)
        st.histDisp[3 * (row + s) + a] = kept ? st.histDisp[3 * (row + s + w) + a] : 0.0;
    }
    st.wallContacts[i] = 0;
  }
  st.listValid = 0;
}

} // namespace

void DemSystem::startFromState(const std::string& path) {
  Impl& m = *_impl;
  HostState st;
  StateMeta meta;
  readStateFile(path, st, meta);
  // Materials by name where the file names them.
  const auto& materials = m.config.materials;
  if (!meta.materialNames.empty()) {
    std::vector<int> to(meta.materialNames.size(), -1);
    for (std::size_t k = 0; k < to.size(); ++k) {
      for (std::size_t j = 0; j < materials.size(); ++j) {
        if (materials[j].name == meta.materialNames[k])
          to[k] = static_cast<int>(j);
      }
    }
    for (std::size_t i = 0; i < st.n; ++i) {
      const int k = st.material[i];
      COREDEM_CHECK(k >= 0 && static_cast<std::size_t>(k) < to.size(),
                    "state file '{}': particle {} has material index {}, the file names {}", path,
                    i, k, to.size());
      COREDEM_CHECK(to[k] >= 0,
                    "state file '{}': its particles of material '{}' have no material of that "
                    "name in this case: add it to materials (the particles keep their sizes, "
                    "masses and temperatures; the material gives the contact and heat properties)",
                    path, meta.materialNames[k]);
      st.material[i] = to[k];
    }
  }
  dropWallHistory(st);
  m.adoptState(path, st);
}

void DemSystem::Impl::adoptState(const std::string& path, HostState& st) {
  Impl& m = *this;
  COREDEM_CHECK(st.nSpecies == static_cast<int>(m.config.solidSpecies.size()),
                "state file '{}' has {} solid species, the config {}: the particles keep their "
                "compositions, so solid_species must be the same",
                path, st.nSpecies, m.config.solidSpecies.size());
  COREDEM_CHECK(st.historySlots >= 1, "state file '{}': bad history_slots", path);
  double rmax = 0;
  std::vector<double> minMass(m.config.materials.size(), std::numeric_limits<double>::infinity());
  std::vector<double> minRadius(m.config.materials.size(), 1.0); // of the lightest (dtDemMax)
  for (std::size_t i = 0; i < st.n; ++i) {
    rmax = std::max(rmax, st.radius[i]);
    if (st.material[i] >= 0 && st.material[i] < static_cast<int>(minMass.size())) {
      const double mi = restartMass(m.config, st, i);
      if (mi < minMass[st.material[i]]) {
        minMass[st.material[i]] = mi;
        // the radius of that mass (with chemistry: the initial one, as restartMass)
        minRadius[st.material[i]] = std::cbrt(mi / (st.density[i] * kernels::sphereVolume(1.0)));
      }
    }
    COREDEM_CHECK(
        st.material[i] >= 0 && st.material[i] < static_cast<int>(m.config.materials.size()),
        "state file '{}': particle {} has material {} not in the config", path, i, st.material[i]);
  }
  COREDEM_CHECK(rmax <= m.setup.maxRadius * (1 + 1e-12) || m.nParticles == 0,
                "state file '{}' holds particles larger (r = {}) than the configured sets (r = {})",
                path, rmax, m.setup.maxRadius);
  if (m.nParticles == 0 && rmax > 0) {
    // Built without particle sets: take the neighbour cell size from the file.
    m.setup.maxRadius = rmax;
    m.setup.skin = m.config.neighbour.skinFactor * 2.0 * rmax;
    if (m.config.heat.enabled && HeatTerms::of(m.setup.heat, m.setup.coupled).lensConduction)
      m.setup.reach = m.config.heat.lensFraction * rmax;
    m.engine.reset();
    m.engine = m.makeEngine();
  }
  m.engine->setState(st);
  m.nParticles = st.n;
  m.dtMax = coredem::dem::dtDemMax(m.config, minMass, minRadius);
}

double DemSystem::time() const {
  return _impl->time.time();
}
std::uint64_t DemSystem::step() const {
  return _impl->step;
}
std::size_t DemSystem::particleCount() const {
  return _impl->nParticles;
}
std::size_t DemSystem::cellCount() const {
  return _impl->setup.nCells;
}
std::string DemSystem::backendName() const {
  return _impl->engine->name();
}
std::string DemSystem::configHash() const {
  return _impl->hash;
}
const DemConfig& DemSystem::config() const {
  return _impl->config;
}

ParticleData DemSystem::particles() const {
  ParticleData p;
  _impl->engine->particles(p);
  return p;
}

void DemSystem::setVelocities(std::span<const double> velocityByGid,
                              std::span<const double> omegaByGid) {
  Impl& m = *_impl;
  HostState s = m.engine->state();
  COREDEM_CHECK(velocityByGid.empty() || velocityByGid.size() == 3 * s.n,
                "setVelocities: {} velocity values, expected {}", velocityByGid.size(), 3 * s.n);
  COREDEM_CHECK(omegaByGid.empty() || omegaByGid.size() == 3 * s.n,
                "setVelocities: {} angular velocity values, expected {}", omegaByGid.size(),
                3 * s.n);
  for (double v : velocityByGid)
    COREDEM_CHECK(std::isfinite(v), "setVelocities: a velocity is not finite");
  for (double v : omegaByGid)
    COREDEM_CHECK(std::isfinite(v), "setVelocities: an angular velocity is not finite");
  for (std::size_t i = 0; i < s.n; ++i) {
    const std::size_t g = static_cast<std::size_t>(s.gid[i]);
    COREDEM_CHECK(s.gid[i] >= 0 && g < s.n,
                  "setVelocities: global ids are not 0..N-1 (state read from a file "
                  "with other ids); set velocities through ParticleSet instead");
    for (int d = 0; d < 3; ++d) {
      if (!velocityByGid.empty())
        s.vel[3 * i + d] = velocityByGid[3 * g + d];
      if (!omegaByGid.empty())
        s.omega[3 * i + d] = omegaByGid[3 * g + d];
    }
  }
  m.engine->setState(s);
}

std::size_t DemSystem::contactCount() const {
  return _impl->engine->pairContacts() + _impl->engine->wallContacts();
}
std::size_t DemSystem::pairContactCount() const {
  return _impl->engine->pairContacts();
}
std::array<double, 3> DemSystem::wallForce() const {
  return _impl->engine->wallForce();
}
std::size_t DemSystem::memoryBytes() const {
  return _impl->engine->memoryBytes();
}
StageTimes DemSystem::stageTimes() const {
  return _impl->engine->times();
}
void DemSystem::resetStageTimes() {
  _impl->engine->times() = StageTimes{};
}
HeatTotals DemSystem::heatTotals() const {
  return _impl->engine->heatTotals();
}
ChemistryTotals DemSystem::chemistryTotals() const {
  return _impl->engine->chemistryTotals();
}

double DemSystem::thermalEnergy() const {
  const ParticleData p = particles();
  double e = 0.0;
  for (std::size_t i = 0; i < p.count; ++i)
    e += p.mass[i] * _impl->config.materials[static_cast<std::size_t>(p.material[i])].cp *
         p.temperature[i];
  return e;
}

} // namespace coredem::dem
