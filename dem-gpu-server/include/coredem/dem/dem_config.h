#pragma once
/// @file
/// The DEM's configuration, `coredem::dem::DemConfig`: plain data (materials, particle sets,
/// walls, coupling grid, species, models, heat and chemistry options) from which DemSystem is
/// built (dem_system.h) and to which the `models:` keys of a case are applied (models.h). The
/// orchestrator fills it to plan the sub-cycling with the DEM's own Δt_DEM,max, without the
/// DEM system itself.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "coredem/dem/chemistry_options.h"
#include "coredem/dem/heat_options.h"
#include "coredem/dem/kernels/contact_law.h"
#include "coredem/dem/kernels/drag.h"

namespace coredem::dem {

/// Contact properties of one solid material (docs/physics.md §2.1, Eqs. 9–13).
/// Pairs of different materials use the contact law's mixing (linear spring–dashpot:
/// k_n = 2 k_a k_b/(k_a+k_b); Hertz–Mindlin: E*, G*; both: e_n = min(e_a, e_b),
/// μ = min(μ_a, μ_b) [C]) unless DemConfig::materialPairs names the pair; particle–wall contacts
/// use the particle's material and the wall's (Wall::material; by default the particle's own)
/// with m_eff = m_i (the wall is rigid and immobile).
struct Material {
  std::string name = "default";
  double kn = 1000.0;          ///< normal spring stiffness k_n (N/m), linear spring–dashpot
  double youngsModulus = 0.0;  ///< Young's modulus E (Pa), Hertz–Mindlin (0: not given)
  double poissonRatio = 0.3;   ///< Poisson's ratio ν (-), in (−1, 0.5), Hertz–Mindlin
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
  /// Index into DemConfig::materials of the wall's contact material; −1 (the default): each
  /// particle meets it with its own material (the behaviour before walls had materials).
  int material = -1;

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
  int material = -1; ///< contact material (index into DemConfig::materials); −1 as Wall::material
};

/// The contact properties of one pair of materials that override the contact law's mixing
/// (docs/case-schema.md `material_pairs`): NaN keeps the mixed value.
struct MaterialPair {
  int a = 0, b = 0;                                     ///< indices into DemConfig::materials
  double en = std::numeric_limits<double>::quiet_NaN(); ///< restitution e_n (-), (0, 1]
  double mu = std::numeric_limits<double>::quiet_NaN(); ///< friction μ (-), ≥ 0
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
  std::vector<MaterialPair> materialPairs; ///< per-pair overrides of e_n and μ (at most one a pair)
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
  double dtFactor = 50.0;   ///< Δt_DEM,max = min(t_0,min / dtFactor, Δt_s) (physics.md §2.1)
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

} // namespace coredem::dem
