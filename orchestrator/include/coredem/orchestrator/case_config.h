#pragma once
/// @file
/// The case file `case.yaml` (docs/case-schema.md): loading, validation against the schema,
/// and the parsed configuration. Every error names the file, line, key and what is allowed,
/// and is thrown as CaseError (exit code 2 in the CLI).

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <coredem/common/check.h>
#include <coredem/common/yaml_section.h>
#include <coredem/orchestrator/time_handler.h>

namespace coredem::v1 {
class Configure;
}

namespace coredem::orchestrator {

/// A case file that does not follow the schema (or a file it names that is missing).
using CaseError = ConfigError;

/// Longest case name (bytes): the run folder's name (a file name of most file systems).
inline constexpr std::size_t kMaxCaseNameBytes = 200;
/// Longest case description (bytes).
inline constexpr std::size_t kMaxCaseDescriptionBytes = 4096;

using Vec3 = std::array<double, 3>;

struct GridConfig {
  Vec3 origin{};
  Vec3 spacing{};
  std::array<std::uint64_t, 3> cells{};
};

struct SpeciesConfig {
  std::string name;
  double molarMass = 0.0; ///< kg/mol
};

/// gas_properties (docs/case-schema.md). model constant: the four properties are given (and equal
/// the OpenFOAM case's transportProperties). model ideal_gas: they are computed by the CFD from T,
/// p and the composition (NASA-7 cp, Sutherland viscosity; gas_data.h); here they hold the initial
/// gas (temperature, pressure, and the mixture's state at them, see parseCase), and coredem writes
/// constant/thermophysicalProperties into the run's copy of the OpenFOAM case.
struct GasPropertiesConfig {
  std::string model = "constant"; ///< constant | ideal_gas
  bool idealGas() const { return model == "ideal_gas"; }
  double density = 1.204, viscosity = 1.81e-5, conductivity = 0.0257, cp = 1005.0,
         temperature = 293.15, pressure = 101325.0;
  double diffusivity = 2e-5; ///< ideal_gas: species diffusivity D, m2/s
};

struct MaterialConfig {
  std::string name;
  double density = 0.0, kN = 0.0, eN = 0.0, friction = 0.0; ///< kN 0: not given (Hertz–Mindlin)
  std::optional<double> ktFactor, etatFactor;
  double cp = 0.0, conductivity = 0.0, emissivity = 0.0;
  /// Hertz–Mindlin (protocol v1.6): Young's modulus (Pa) and Poisson's ratio (-).
  std::optional<double> youngsModulus, poissonRatio;
};

/// material_pairs[]: contact properties of one pair of materials replacing the law's mixing
/// (protocol v1.6).
struct MaterialPairConfig {
  std::string a, b;                   ///< material names (may be the same)
  std::optional<double> eN, friction; ///< unset: the mixed value
};

struct ParticleSetConfig {
  std::string name;
  std::string material;
  std::uint64_t count = 0;
  double diameter = 0.0, density = 0.0, temperature = 293.15;
  std::vector<std::pair<std::string, double>> composition;
  std::string packing = "lattice";
  Vec3 regionMin{}, regionMax{};
  std::uint64_t seed = 1;
  Vec3 velocity{};
  std::vector<Vec3> positions; ///< packing "explicit": one centre per particle (count = size)
};

struct PlaneConfig {
  Vec3 point{}, normal{};
  std::string material; ///< contact material (v1.6); empty: each particle's own
};

/// A cylinder or cone wall about an axis (walls.cylinders[], walls.cones[]; protocol v1.4).
struct RevolvedWallConfig {
  bool cone = false; ///< false: walls.cylinders[index], true: walls.cones[index]
  std::size_t index = 0;
  Vec3 point{};                          ///< m, on the axis (axial coordinate 0)
  Vec3 axis{0, 0, 1};                    ///< unit direction (normalised from case.yaml)
  double radiusFrom = 0.0;               ///< m, radius at `from` (a cylinder's radius)
  double radiusTo = 0.0;                 ///< m, radius at `to` (a cylinder: = radiusFrom)
  bool finite = true;                    ///< false: an infinite cylinder (no from/to)
  double from = 0.0, to = 0.0;           ///< m along the axis from `point`, from < to (when finite)
  std::string side = "inside";           ///< inside | outside | both
  bool capStart = false, capEnd = false; ///< flat discs closing `from` / `to`
  std::string material;                  ///< contact material (v1.6); empty: each particle's own
  /// "walls.cylinders[0]" (messages)
  std::string key() const;
};

/// A triangle-mesh wall read from an STL file or built from patches of the CFD mesh
/// (walls.meshes[]; protocol v1.4).
struct MeshWallConfig {
  std::string file;           ///< as written in case.yaml, relative to the case folder; or empty
  std::filesystem::path path; ///< absolute: the STL file, or the CFD case's constant/polyMesh
  /// from_cfd: patches of the CFD mesh (cfd.case/constant/polyMesh) whose faces are the wall;
  /// empty for an STL file.
  std::vector<std::string> fromCfd;
  /// What messages and Configure call the wall: `file`, or "<cfd.case>/constant/polyMesh
  /// patches a, b" (stable across restarts: part of the DEM's configuration hash).
  std::string name;
  double scale = 1.0;           ///< coordinates multiplied by this (0.001: file in mm)
  bool closed = false;          ///< a closed surface is required (and particles must be inside)
  std::vector<double> vertices; ///< m, x0,y0,z0,x1,... (welded, scaled)
  std::vector<std::int32_t> triangles; ///< 3 vertex indices per triangle
  std::string material;                ///< contact material (v1.6); empty: each particle's own
  /// The key of case.yaml the wall comes from: "file" or "from_cfd" (messages).
  const char* sourceKey() const { return fromCfd.empty() ? "file" : "from_cfd"; }
};

struct WallsConfig {
  std::optional<std::pair<Vec3, Vec3>> box;
  std::string boxMaterial; ///< contact material of the box's faces (v1.6); empty: the particle's
  std::vector<PlaneConfig> planes;
  std::vector<RevolvedWallConfig> revolved; ///< cylinders then cones, in case.yaml order
  std::vector<MeshWallConfig> meshes;
  std::string material;
  double temperature = 0.0;
};

struct DemConfig {
  std::string endpoint; ///< empty: coredem starts coredem-dem itself
  std::string backend = "cpu";
  int threads = 0;                 ///< 0: let the server choose
  double timeoutSeconds = 60;      ///< deadline of every request to D
  std::filesystem::path serverKey; ///< file with D's CURVE public key (Z85); empty: no CURVE
  /// With serverKey: this user's client key (client.secret, or the folder holding it) for a D
  /// with an allow-list (coredem-dem --client-keys); empty: a throw-away pair per run.
  std::filesystem::path clientKey;
  bool timers = false; ///< dem.timers: coredem-dem --timers (RUN/timers-dem.json)
};

struct CfdConfig {
  /// A row of the participant table (participants.h); the default is its first row.
  std::string participant = "coredem-gas";
  std::string gasKey = "gas"; ///< cfd.gas_key: key of the prescribed-gas section
  std::string caseFolder; ///< cfd.case: the participant's input folder, relative to the case folder
  double timeoutSeconds = 60; ///< deadline for C's next StepDone
  bool timers = false;        ///< cfd.timers: the participant's stage timers (RUN/timers-cfd.json)
  /// cfd.ranks: MPI ranks of a decomposed participant (mpirun -np K ... -parallel); 1 = serial.
  int ranks = 1;
};

/// inlets[i] (docs/case-schema.md "Inlets and outlets"): a patch of the CFD mesh through which
/// gas enters, written into the CFD participant's case (the one source of truth: a campaign
/// sweeps it by key).
struct InletConfig {
  std::string patch; ///< a patch of the CFD mesh
  /// Superficial gas velocity (m/s): the gas volume flow per unit area of the patch, whatever
  /// the particles in the cells at the inlet.
  Vec3 velocity{0.0, 0.0, 0.0};
  /// superficial_velocity_table: rows (t, ux, uy, uz), t strictly increasing, linear in
  /// between and held beyond the ends; empty: the constant `velocity`.
  std::vector<std::array<double, 4>> velocityTable;
  std::optional<double> temperature; ///< K; nullopt: the CFD case's own
  /// Mass fractions in the order of the case's species (all of them); empty: the CFD case's own.
  std::vector<double> massFractions;
};

/// outlets[i]: a patch of the CFD mesh where the gas leaves at the case's pressure (p fixed,
/// the velocity from the flow).
struct OutletConfig {
  std::string patch;
};

/// coupling: how CFD and DEM steps follow each other (docs/coupling-schemes.md).
struct CouplingConfig {
  /// sequential: the CFD waits for the DEM's sources of the same step; staggered: the CFD advances
  /// step n with the sources the DEM computed in step n-1 while the DEM computes step n.
  std::string scheme = "sequential";
  bool staggered() const { return scheme == "staggered"; }
};
struct CheckpointConfig {
  std::int64_t everySteps = 0; ///< 0 = off
  double everySeconds = 0.0;   ///< wall-clock seconds, 0 = off
  int keep = 3;
};

struct OutputConfig {
  /// True when any synchronized output (particles and gas at the same step) is configured.
  bool any() const { return snapshotEvery > 0 || everySeconds > 0.0; }
  /// Steps between synchronized outputs (particle snapshot + CFD fields), 0 = none.
  std::int64_t snapshotEvery = 0;
  /// Simulated seconds between synchronized outputs (at multiples of it; Δt_CFD is shortened to
  /// land on them), 0 = none.
  double everySeconds = 0.0;
  std::int64_t timeseriesEvery = 1; ///< steps between timeseries rows
};

/// One term of a reaction (case.yaml reactions[].terms[]): a gas or solid species and ν.
struct ReactionTermConfig {
  std::string species;
  double nu = 0.0; ///< mol per mol of reaction, < 0 reactant
};

/// A heterogeneous reaction defined by data (docs/case-schema.md "reactions").
struct ReactionConfig {
  std::string name;
  std::vector<ReactionTermConfig> terms;
  std::string law = "constant"; ///< constant | arrhenius
  double A = 0.0, beta = 0.0, E = 0.0;
  std::string orderSpecies; ///< arrhenius: gas species of the concentration factor (empty: none)
  double order = 0.0;
  double heatOfReaction = 0.0; ///< J/mol (> 0 endothermic)
  bool heatFromNasa7 = false;  ///< heat_of_reaction: nasa7
};

/// Built-in models and switches (docs/case-schema.md "chemistry").
struct ChemistryConfig {
  bool present = false;          ///< the case has a chemistry section
  bool charGasification = false; ///< clg.char_gasification
  std::string charStoichiometry = "carbon";
  bool ocReduction = false; ///< clg.oc_reduction
  bool wgs = false;         ///< clg.wgs
  std::string wgsEquilibrium = "yoon_denn";
  std::vector<std::pair<std::string, double>> kinetics; ///< clg kinetic overrides by name
  std::optional<double> removalFraction;                ///< default 0.1
  std::optional<bool> reactionHeat;                     ///< default on
};

/// A validated case.
struct CaseConfig {
  std::filesystem::path caseDir;  ///< absolute
  std::filesystem::path caseFile; ///< absolute path of case.yaml
  std::string text;               ///< the case file's bytes (hashed into the config hash)
  std::string configHash;         ///< SHA-256 of text

  std::string name;
  std::string description;
  double endTime = 0.0;
  DtPolicyConfig dt;
  double dtDem =
      0.0; ///< time.dt_dem: forced Δt_DEM (s), n_sub = dt/dt_dem; 0 = the DEM's Δt_DEM,max
  GridConfig grid;
  Vec3 gravity{0.0, 0.0, -9.81};
  std::vector<SpeciesConfig> species;
  GasPropertiesConfig gasProperties;
  std::vector<MaterialConfig> materials;
  std::vector<MaterialPairConfig> materialPairs; ///< material_pairs (protocol v1.6)
  std::vector<ParticleSetConfig> particles;
  std::filesystem::path initialState; ///< absolute, empty when particle sets are used
  WallsConfig walls;
  std::vector<std::pair<std::string, std::string>> models;
  /// Clip ε_min of the gas fraction, from models: {eps_min} (or its old spellings): the DEM's
  /// drag and convection and the CFD's gas equations (coredemFoam -epsMin) use this one value.
  double epsMin = 0.35;
  DemConfig dem;
  CfdConfig cfd;
  std::vector<InletConfig> inlets;   ///< inlets (written into the CFD participant's case)
  std::vector<OutletConfig> outlets; ///< outlets (written into the CFD participant's case)
  CouplingConfig coupling;
  CheckpointConfig checkpoint;
  OutputConfig output;
  bool hasGasSection = false;
  // Chemistry (protocol v1.1; docs/thermochemistry.md).
  std::vector<SpeciesConfig> solidSpecies; ///< particle species (composition columns)
  std::vector<ReactionConfig> reactions;
  ChemistryConfig chemistry;
  /// True when the case uses chemistry (solid_species, reactions or chemistry): needs a v1.1
  /// server.
  bool usesChemistry() const {
    return !solidSpecies.empty() || !reactions.empty() || chemistry.present;
  }
  /// True when the case has cylinder, cone or mesh walls: needs a v1.4 server
  /// (protocol::kMinorWallShapes).
  bool usesWallShapes() const { return !walls.revolved.empty() || !walls.meshes.empty(); }
  /// What of the contact materials of protocol v1.6 the case uses ("" when none): material
  /// pairs, wall materials, the hertz-mindlin law (the Configure fields a v1.5 server ignores).
  std::string contactMaterialsUsed() const;
};

/// Loads and validates CASE_DIR/case.yaml (or a file path). Throws CaseError.
CaseConfig loadCase(const std::filesystem::path& caseDirOrFile);
/// The case file of a case folder (its case.yaml) or of a case file (itself).
std::filesystem::path caseFileOf(const std::filesystem::path& caseDirOrFile);

/// Parses case text as if read from `file` (relative paths resolve against `caseDir`).
CaseConfig parseCase(const std::string& text, const std::filesystem::path& file,
                     const std::filesystem::path& caseDir);

/// The largest temperature difference (K) between the gas (gas_properties.temperature) and a
/// particle set or fixed-temperature walls; 0 with models.heat off. The gas model defaults to
/// ideal_gas where it is > 0 (docs/case-schema.md "gas_properties").
double largestGasTemperatureDifference(const CaseConfig& config);

/// Adds the chemistry of `config` (solid species, reactions, chemistry) to a Configure (v1.1
/// fields). Defined in case_chemistry.cpp (library coredem::orchestrator, which links the
/// protocol).
void addChemistryToConfigure(const CaseConfig& config, v1::Configure& configure);

/// Index of a material by name, or -1.
int materialIndex(const CaseConfig& config, const std::string& name);

} // namespace coredem::orchestrator
