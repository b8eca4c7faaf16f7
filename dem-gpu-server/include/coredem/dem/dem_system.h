#pragma once
/// @file
/// The DEM core's public API: `coredem::dem::DemSystem`, built from a plain `DemConfig`.
///
/// Typical use by the server (one CFD step, docs/architecture.md):
/// @code
///   coredem::dem::DemSystem dem(config, coredem::dem::BackendKind::Auto, threads);
///   int nSub = coredem::dem::TimeHandler::subStepsFor(dtCfd, dem.dtDemMax());
///   dem.setGasFields(view);                          // per-cell arrays, frozen for the step
///   const coredem::dem::CellSources& s = dem.advance(dtCfd, nSub);  // sub-step averages
///   dem.writeState("state.h5");                      // bitwise restart with readState
/// @endcode
///
/// Units are SI everywhere. Coupling cells are numbered cell = i + nx*(j + ny*k).
/// All methods throw coredem::UserError on bad input, with a message that says what to fix.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "coredem/dem/dem_config.h"

namespace coredem::dem {

/// Which backend runs the kernels. `Auto` = Cuda if a CUDA device is present, else Cpu.
/// `CudaSim` ("cuda-sim", for tests and debugging): the cpu kernels under the cuda backend's
/// memory model (separate device memory filled with garbage, explicit copies), so that a
/// missing host↔device synchronisation shows without a GPU; never chosen by `Auto`.
enum class BackendKind { Cpu, Cuda, Auto, CudaSim };

/// Parses "cpu" | "cuda" | "auto" | "cuda-sim" (UserError otherwise).
BackendKind parseBackend(const std::string& name);
/// "cpu", "cuda", "auto" or "cuda-sim".
std::string backendName(BackendKind kind);
/// True when this build contains the CUDA backend (COREDEM_CUDA_ENABLED).
bool cudaBackendBuilt();
/// Number of visible CUDA devices (0 when the CUDA backend is not built, when there is no GPU
/// or driver, and when the CUDA runtime fails: probeCuda() tells these apart).
int cudaDeviceCount();

/// What the CUDA runtime says about this machine.
struct CudaProbe {
  bool built = false; ///< this build contains the CUDA backend
  int devices = 0;    ///< usable devices (0 when none, and on error)
  /// Empty, or a CUDA runtime failure (e.g. a driver too old for this build's runtime) with
  /// CUDA's own message and what to do: a broken GPU setup, never reported as "no device".
  std::string error;
  /// When devices == 0 without error: why (not built, no driver, no device, CUDA_VISIBLE_DEVICES).
  std::string note;
};
/// Asks the CUDA runtime (cudaGetDeviceCount, driver and runtime versions) each call.
CudaProbe probeCuda();

/// What made the backends with a separate device (cuda, cuda-sim) wait, counted since the
/// process started, all systems together (the cpu backend counts nothing). Differences over a
/// run divided by its sub-steps give the per-sub-step figures coredem-bench dem reports.
struct BackendSyncCounts {
  std::uint64_t hostRoundTrips = 0; ///< device → host copies the host waits for (incl. reductions)
  std::uint64_t deviceSyncs = 0;    ///< explicit device-wide synchronisations
  std::uint64_t launches = 0;       ///< kernel launches (CUB calls count as their kernels)
};
BackendSyncCounts backendSyncCounts();

/// Read-only view of the per-cell gas fields of one CFD step (N = grid cell count,
/// ns = gasSpecies.size()). Spans must outlive the setGasFields call only (they are copied).
struct GasFieldsView {
  std::span<const double> ug;     ///< u_g, N*3 (m/s), interleaved x,y,z per cell
  std::span<const double> gradP;  ///< ∇p, N*3 (Pa/m)
  std::span<const double> Tg;     ///< T_g, N (K)
  std::span<const double> rhoG;   ///< ρ_g, N (kg/m³)
  std::span<const double> muG;    ///< μ_g, N (Pa s)
  std::span<const double> kappaG; ///< κ_g, N (W/m/K)
  std::span<const double> cpG;    ///< c_p,g, N (J/kg/K)
  std::span<const double> Yg;     ///< Y_g, N*ns (-), species fastest
  /// Optional fluid fraction φ_f of each cell's volume, N (-), in [0, 1]; empty: 1 everywhere.
  /// PCM then takes ε_g = 1 − V_s/(φ_f V_c) for the closures (drag, heat, WGS) and a particle
  /// in a cell with φ_f = 0 is an error naming it; the sources stay per V_c.
  std::span<const double> fluidFraction;
  /// Optional heat for the particles, N (J per m³ of coupling cell, either sign; empty: none):
  /// the heat the gas removed from each cell in its last step beyond what the DEM booked
  /// (protocol 1.5 Q_split). The next advance() gives Q_split[c]·V_c to the particles of cell c at
  /// its start, in proportion to their gas conductance G_i = h_i A_i (all G_i zero: to m_i c_p,i),
  /// ΔT_i = R_i/(m_i c_p,i), booked in HeatTotals::convection; a cell without particles books it
  /// in HeatTotals::splitUnassigned (a warning names the first such cell, once). Given once: a
  /// second advance() without new gas fields does not give it again; evaluateSources() never.
  std::span<const double> heatToParticles;
};

/// Per-cell sources for the CFD, averaged over the sub-steps of one advance() (docs/physics.md
/// §1.1). Heat: gas energy source −(H T_g − H_Tp) (W/m³), H = Σ h_i A_i/V_c, H_Tp = Σ h_i A_i
/// T_p,i/V_c (docs/heat-coupling.md). Species: R_species = (1/V_c) Σ ṁ_gas,i (heterogeneous,
/// averaged over the sub-steps) + WGS per cell; Q_hom: WGS heat into the gas
/// (docs/thermochemistry.md).
struct CellSources {
  std::vector<double> epsG;     ///< ε_g (-), N
  std::vector<double> kSl;      ///< K_sl = (1/V_c) Σ β V_p/(1-ε) (kg/m³/s), N
  std::vector<double> kSlUs;    ///< K_sl·U_s = (1/V_c) Σ β V_p/(1-ε) v_p (kg/m²/s²), N*3
  std::vector<double> heatH;    ///< H, implicit gas→particle heat coefficient (W/m³/K), N
  std::vector<double> heatHTp;  ///< H·T̄_p (W/m³), N
  std::vector<double> rSpecies; ///< R_species (kg/m³/s), N*ns
  std::vector<double> qHom;     ///< homogeneous reaction heat (W/m³), N
  /// Net radiation heat the particles of the cell gave their environment, per V_c, averaged
  /// over the sub-steps like H and H_Tp (W/m³, N; positive = heat to the gas): −(1/V_c) ⟨Σ_i
  /// Q_rad,i⟩. Σ_c qRad V_c Δt_CFD = −Δ HeatTotals::radiation of the window (round-off). Sent as
  /// the Sources array Q_rad to a CFD peer of protocol 1.3 or later (docs/heat-coupling.md).
  std::vector<double> qRad;
  /// Momentum of the mass the particles give the gas, per V_c, averaged over the sub-steps like
  /// rSpecies (N/m³, N*3): (1/V_c) ⟨Σ_i ṁ_i u_i⟩ with ṁ_i the net gas mass particle i releases
  /// (kg/s, Σ_k of its species rates; negative when it takes gas) and u_i its velocity in the
  /// sub-step: the mass leaves the particle at the particle's velocity. Sent as the Sources array
  /// mom_p to a CFD peer of protocol 1.5 or later (docs/physics.md §1.1).
  std::vector<double> momP;
};

/// Host copy of the particle state (for tests, snapshots and the server), in the system's
/// current internal order (which changes on neighbour-list rebuilds; use globalId to match).
struct ParticleData {
  std::size_t count = 0;
  int nSpecies = 0;
  std::vector<double> position, velocity, angularVelocity,
      force; ///< N*3 (force: last sub-step, contacts+walls+gas, no gravity)
  std::vector<double> radius, mass, density, temperature; ///< N
  std::vector<double> species;                            ///< N*nSpecies
  std::vector<std::int32_t> material;                     ///< N
  std::vector<std::int64_t> globalId;                     ///< N
  std::vector<double> initialDiameter;                    ///< N, d_p0 (m): removal reference
};

/// Wall-clock seconds spent per stage since construction (or resetStageTimes()).
struct StageTimes {
  double neighbour = 0; ///< cell keys, sort, reorder, neighbour lists
  double contact = 0;   ///< particle–particle and wall contact forces
  double drag = 0;      ///< gas forces: PCM cell, drag law, −V_p∇p (coupled runs only)
  double integrate = 0; ///< motion update and temperature updates
  double coupling = 0;  ///< PCM ε_g and cell-source deposition
  double heat = 0;      ///< heat sources (conduction, convection, radiation) and their deposition
  double chemistry = 0; ///< reaction rates, mass/diameter update, species deposition, WGS, removal
  std::uint64_t rebuilds = 0;
};

/// Thrown by DemSystem::advance() when its interrupt flag was set during the step (a signal to
/// the server): the state is that of a partial CFD step, fit only for ending the run.
class Interrupted : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

/// The DEM system: particles, contacts and the sub-cycled integrator on one backend.
/// Not thread-safe: call from one thread. On the cpu backend results are bitwise
/// reproducible run to run and independent of the thread count (every particle gathers its
/// own forces from a full neighbour list; no atomics, no order-dependent reductions).
/// Integrator: symplectic Euler (v, ω first, then x), one force evaluation per sub-step.
class DemSystem {
public:
  /// @pre config valid (UserError otherwise: what is wrong and how to fix it).
  /// @param threads OpenMP threads for the cpu backend (0 = OpenMP default).
  explicit DemSystem(const DemConfig& config, BackendKind backend = BackendKind::Cpu,
                     int threads = 0);
  ~DemSystem();
  DemSystem(const DemSystem&) = delete;
  DemSystem& operator=(const DemSystem&) = delete;

  /// Largest stable DEM step: min over present material pairs and walls of t_col / dtFactor
  /// (docs/physics.md Eq. 12 with Eq. 13 damping), using the lightest particle of each material.
  double dtDemMax() const;

  /// Copies the gas fields used (frozen) during the next advance() calls.
  /// @pre a coupling grid is configured; every span has the size documented in GasFieldsView
  ///      (optional: kappaG, cpG, Tg, Yg may be empty); all values finite, ρ_g, μ_g > 0.
  void setGasFields(const GasFieldsView& gas);

  /// Advances by dtCfd in nSub equal sub-steps (Δt_DEM = dtCfd/nSub), returns the
  /// sub-step-averaged cell sources (empty vectors when no coupling grid).
  /// @pre dtCfd > 0, nSub >= 1, dtCfd/nSub <= dtDemMax()·(1 + 1e-12).
  const CellSources& advance(double dtCfd, int nSub);

  /// The cell sources of the current state with the gas fields set last, without advancing:
  /// one sub-step of `dtDem` is evaluated (window of one sub-step: the forces, heat and reaction
  /// rates of the current configuration, ε_g of the current positions) and the particle state,
  /// contact history and ledgers are put back as they were, so that the next advance() is
  /// bitwise the one without this call. The staggered coupling scheme sends these as the sources
  /// of its first step (docs/coupling-schemes.md).
  /// @pre 0 < dtDem <= dtDemMax()·(1 + 1e-12).
  const CellSources& evaluateSources(double dtDem);

  /// A flag read before every sub-step of advance() (e.g. set from a signal handler): once it
  /// is set, advance() stops within a sub-step and throws Interrupted. nullptr: none. The flag
  /// must outlive the system.
  void setInterruptFlag(const std::atomic<bool>* flag);

  /// Writes the full state (particles, contact history, neighbour lists, time) to HDF5.
  /// `protocolVersion` is the coupling protocol of the server that writes it ("1.1"), recorded
  /// in /meta; a system used without a server leaves it empty and the file says "none".
  void writeState(const std::string& path, const std::string& protocolVersion = {}) const;
  /// Replaces the state by the one in `path`; continuing is bitwise identical to not
  /// having stopped (cpu backend; gas fields must be set again). A system configured without
  /// particle sets takes all particles from the file; Δt_DEM,max is recomputed from them.
  /// @pre written by a system with the same config hash (else UserError naming both).
  void readState(const std::string& path);
  /// A new start from the particles of another run's state file (a checkpoint or a snapshot,
  /// any configuration): positions, velocities, angular velocities, radii, masses, densities,
  /// temperatures, compositions, initial diameters and the tangential history of particle
  /// pairs; the time, step and ledgers start at 0, the walls' history is dropped (the walls
  /// may differ) and each particle takes the material of the same name in this configuration
  /// (by index for files that do not name them). Δt_DEM,max is recomputed from the particles.
  /// @pre the file's solid species count is this configuration's (else UserError); every
  /// particle's material exists here (else UserError naming it).
  void startFromState(const std::string& path);

  double time() const;        ///< simulated time (s)
  std::uint64_t step() const; ///< DEM sub-steps taken
  std::size_t particleCount() const;
  std::size_t cellCount() const;   ///< coupling cells (0 without a grid)
  std::string backendName() const; ///< "cpu", "cuda" or "cuda-sim"
  std::string
  configHash() const; ///< 16 hex digits over materials, walls, gravity, grid, species, options
  const DemConfig& config() const;

  ParticleData particles() const; ///< host copy of the state
  /// Overwrites velocities / angular velocities by global id order (size N*3 each; empty = keep).
  void setVelocities(std::span<const double> velocityByGid, std::span<const double> omegaByGid);
  std::size_t
  contactCount() const; ///< particle–particle contacts (pairs) + wall contacts, last sub-step
  std::size_t pairContactCount() const; ///< particle–particle contact pairs, last sub-step
  std::array<double, 3>
  wallForce() const; ///< Σ force exerted by all walls on particles, last sub-step (N)
  std::size_t memoryBytes() const; ///< bytes of particle, neighbour and contact storage
  StageTimes stageTimes() const;
  /// Heat the particles received from the gas and from radiation since construction (kept
  /// across writeState/readState), J.
  HeatTotals heatTotals() const;
  /// Chemistry ledgers since construction (kept across writeState/readState): gas released by
  /// particles per species, solid change per species, reaction heat, removed mass (kg, J).
  ChemistryTotals chemistryTotals() const;
  /// Σ m_i c_p,i T_p,i over the particles (J, with the material's constant c_p).
  double thermalEnergy() const;
  void resetStageTimes();

private:
  struct Impl;
  std::unique_ptr<Impl> _impl;
};

} // namespace coredem::dem
