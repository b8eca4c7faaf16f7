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

#include "coredem/dem/chemistry_options.h"
#include "coredem/dem/heat_options.h"
#include "coredem/dem/kernels/contact_law.h"
#include "coredem/dem/kernels/drag.h"

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

/// Contact properties of one solid material (docs/physics.md §2.1, Eqs. 9–13).
/// Pairs of different materials use k_n = 2 k_a k_b/(k_a+k_b), e_n = min(e_a, e_b),
/// μ = min(μ_a, μ_b) [C]; particle–wall contacts use the particle's material with
/// m_eff = m_i (the wall is rigid, immobile, and has the particle's properties).
struct Material {
  std::string name = "default";
  double kn = 1000.0;          ///< normal spring stiffness k_n (N/m)
  double en = 0.97;            ///< normal restitution coefficient e_n (-), 0 < e_n <= 1
  double mu = 0.1;             ///< Coulomb friction coefficient μ (-)
  double ktFactor = 2.0 / 7.0; ///< k_t = ktFactor·k_n (MFiX KT_FAC)
  double etatFactor = 0.5;     ///< η_t = etatFactor·η_n (MFiX DES_ETAT_FAC)
  double cp = 840.0;           ///< specific heat c_p (J/kg/K), > 0 (Eq. 18)
  double conductivity = 1.0;   ///< k_p (W/m/K), ≥ 0 (contact conduction, Eq. 22)
  double emissivity = 0.0;     ///< e_p (-), in [0, 1]; 0: the particle does not radiate (Eq. 27)
};

/// How a ParticleSet places its particles.
enum class Packing {
  Lattice, ///< simple cubic, spacing `spacing` (0: the diameter), sites from regionMin + s/2, x
           ///< fastest
  Random,  ///< non-overlapping uniform random positions in the region, from `seed`
  Explicit ///< the `positions` (and optional `velocities`) given below, one entry per particle
};

/// A group of identical particles placed in an axis-aligned box region.
struct ParticleSet {
  std::string name = "particles";
  int material = 0; ///< index into DemConfig::materials
  Packing packing = Packing::Lattice;
  std::array<double, 3> regionMin{
      0, 0, 0}; ///< region (m): Random keeps spheres inside, Lattice its site centres
  std::array<double, 3> regionMax{0, 0, 0};
  std::size_t count = 0;           ///< number of particles (Explicit: positions.size()/3)
  double diameter = 1e-3;          ///< d_p (m)
  double density = 2500.0;         ///< ρ_p (kg/m³)
  double temperature = 293.15;     ///< T_p (K)
  std::vector<double> composition; ///< solid species mass fractions (sum 1), size = solidSpecies;
                                   ///< empty: all in the first
  double spacing = 0.0;            ///< Lattice spacing (m); 0 = diameter
  std::array<double, 3> velocity{0, 0, 0}; ///< initial velocity (m/s), added to the jitter
  double velocityJitter = 0.0;             ///< each component + uniform[-a, a] (m/s)
  std::uint64_t seed = 12345;              ///< for Random packing and the jitter
  std::vector<double> positions;           ///< Explicit: x0,y0,z0,x1,... (m)
  std::vector<double> velocities;          ///< Explicit (optional): same layout (m/s)
  std::vector<double> angularVelocities;   ///< Explicit (optional): same layout (rad/s)
};

/// The shape of an analytic wall (docs/physics.md "Walls").
enum class WallShape {
  Plane,    ///< infinite plane; particles on the side its normal points to
  Cylinder, ///< finite (start < end) or infinite cylinder about an axis
  Cone      ///< frustum about an axis: radius `radius` at `start`, `radiusEnd` at `end`
};

/// Which side of a cylinder or cone the particles are on.
enum class WallSide {
  Inside,  ///< the axis side: a vessel
  Outside, ///< away from the axis: around a solid insert (a tube, a rod)
  Both     ///< a thin shell touched from either side (e.g. a draft tube)
};

/// A rigid wall: a plane, or a cylinder or cone about an axis (an axial extent, optional flat
/// caps closing either end). Contact regions and features: kernels/wall_contact.h.
struct Wall {
  WallShape shape = WallShape::Plane;
  /// Plane: a point on it. Cylinder/cone: the axis origin (axial coordinate 0).
  std::array<double, 3> point{0, 0, 0};
  /// Plane: the normal towards the particles. Cylinder/cone: the axis direction (the axial
  /// coordinate grows along it). Need not be unit length (normalised).
  std::array<double, 3> normal{0, 0, 1};
  double radius = 0.0;    ///< cylinder radius; cone radius at `start` (m, ≥ 0)
  double radiusEnd = 0.0; ///< cone radius at `end` (m, ≥ 0)
  /// Axial extent (m, from `point` along the axis). A cylinder with both infinite (the
  /// default) is infinite; a cone needs a finite extent.
  double start = -std::numeric_limits<double>::infinity();
  double end = std::numeric_limits<double>::infinity();
  WallSide side = WallSide::Inside;
  bool capStart = false; ///< a flat disc closes the `start` end
  bool capEnd = false;   ///< a flat disc closes the `end` end

  /// A plane through `point` with normal `normal` towards the particles.
  static Wall plane(const std::array<double, 3>& point, const std::array<double, 3>& normal);
  /// A cylinder of radius `radius` about the axis through `point` along `axis`, over
  /// [start, end] (both infinite: an infinite cylinder).
  static Wall cylinder(const std::array<double, 3>& point, const std::array<double, 3>& axis,
                       double radius, double start, double end, WallSide side = WallSide::Inside,
                       bool capStart = false, bool capEnd = false);
  /// A cone (frustum) with radius rStart at `start` and rEnd at `end` along the axis.
  static Wall cone(const std::array<double, 3>& point, const std::array<double, 3>& axis,
                   double start, double end, double rStart, double rEnd,
                   WallSide side = WallSide::Inside, bool capStart = false, bool capEnd = false);
};

/// A triangle-mesh wall (coredem/dem/triangle_mesh.h: read from STL, checked, welded).
struct MeshWall {
  std::string name;                    ///< where it came from (messages)
  std::vector<double> vertices;        ///< x0,y0,z0,... (m)
  std::vector<std::int32_t> triangles; ///< 3 vertex indices per triangle
};

/// Uniform Cartesian coupling grid (PCM cells): cell = i + nx*(j + ny*k). counts = 0: no coupling.
struct CouplingGrid {
  std::array<double, 3> origin{0, 0, 0};
  std::array<double, 3> spacing{0, 0, 0};
  std::array<int, 3> counts{0, 0, 0};
  std::size_t cellCount() const {
    return static_cast<std::size_t>(counts[0]) * counts[1] * counts[2];
  }
};

/// A named chemical species with its molar mass (kg/mol).
struct Species {
  std::string name;
  double molarMass = 0.0;
};

/// Largest NeighbourOptions::historySlots (local arrays in the contact kernel).
inline constexpr int kMaxHistorySlots = 32;

/// Tuning of neighbour search and contact storage (defaults from bench measurements,
/// docs/performance.md "## DEM core").
struct NeighbourOptions {
  double skinFactor =
      0.1; ///< Verlet skin = skinFactor · d_max; lists rebuilt when a particle moved > skin/2
  int historySlots =
      12; ///< tangential-history slots per particle (owned contacts + walls), 1..kMaxHistorySlots
  int initialNeighbourSlots = 16; ///< neighbour-list width per particle (grows automatically)
};

/// Everything needed to build a DemSystem. Plain data; validated by the constructor. The
/// `models:` keys of a case (Configure.options) are applied by applyModelOption (models.h).
struct DemConfig {
  std::vector<Material> materials{Material{}};
  std::vector<ParticleSet> particleSets;
  std::vector<Wall> walls;
  std::vector<MeshWall> meshes; ///< triangle-mesh walls (two-sided), besides `walls`
  std::array<double, 3> gravity{0.0, 0.0, -9.81}; ///< m/s²
  CouplingGrid grid;
  std::vector<Species> solidSpecies; ///< per-particle composition entries
  std::vector<Species> gasSpecies;   ///< Y_g and R_species entries
  NeighbourOptions neighbour;
  kernels::DragLaw drag = kernels::DragLaw::Gidaspow; ///< `models: {drag: ...}` (kernels/drag.h)
  /// `models: {contact: ...}`: the contact law of particles and walls (kernels/contact_law.h).
  kernels::ContactLaw contact = kernels::ContactLaw::LinearSpringDashpot;
  /// Each contact law's parameters (`models: {contact.<law>.<parameter>: ...}`).
  kernels::ParamPack<kernels::ContactLaws> contactLaws{};
  /// Each drag law's parameters (`models: {drag.<law>.<parameter>: ...}`, from its declaration).
  kernels::ParamPack<kernels::DragLaws> dragLaws{};
  double epsMinDrag = 0.35; ///< ε_min clip in drag (docs/physics.md §1.1 [C])
  double dtFactor = 50.0;   ///< Δt_DEM,max = t_col,min / dtFactor (docs/physics.md Eq. 12)
  HeatOptions heat;         ///< particle heat transfer (docs/heat-coupling.md)
  /// Hold every particle in place (`models: {motion: frozen}`, as MFiX's verification cases do):
  /// forces, torques and gravity do not move it, positions stay fixed, velocities are zeroed
  /// every sub-step. Contacts and heat transfer are evaluated as usual; the collision time then
  /// does not limit Δt_DEM (dtDemMax() returns the largest finite double).
  bool frozenMotion = false;
  ChemistryOptions chemistry; ///< reactions, CLG models, removal (docs/thermochemistry.md)
  /// Wall thermal condition (docs/heat-coupling.md "Walls"): > 0 holds every wall at this
  /// temperature (K) with particle–wall conduction (kernels/wall_conduction.h); 0 = adiabatic.
  double wallTemperature = 0.0;
  int wallMaterial = 0; ///< material of the walls (its conductivity is k_w)
  /// A stop flag (e.g. set from a signal handler), read while particles are placed: once set,
  /// the constructor throws Interrupted. It also becomes the system's interrupt flag
  /// (setInterruptFlag). Not part of the configuration hash. nullptr: none.
  const std::atomic<bool>* interrupt = nullptr;

  /// Adds the six planes of the axis-aligned box [lo, hi] (normals pointing inwards).
  void addBox(const std::array<double, 3>& lo, const std::array<double, 3>& hi);
};

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
