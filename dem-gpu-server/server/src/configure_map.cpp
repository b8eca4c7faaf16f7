// v1::Configure -> dem::DemConfig.
#include "configure_map.h"

#include <algorithm>
#include <limits>
#include <map>

#include "coredem/common/check.h"
#include "coredem/dem/kernels/nasa7.h"
#include "coredem/dem/models.h"
#include "coredem/protocol/coupling_scheme.h"
#include "coredem/protocol/initial_state.h"

namespace coredem::server {

namespace {

/// Molar mass (kg/mol) of a species of the DEM core's thermodynamic table by name; 0 if the
/// name is not there.
double builtinMolarMass(const std::string& name) {
  namespace k = coredem::dem::kernels;
  static const std::map<std::string, k::Species> table = {
      {"CO", k::Species::CO},       {"CO2", k::Species::CO2},     {"H2", k::Species::H2},
      {"H2O", k::Species::H2O},     {"N2", k::Species::N2},       {"C", k::Species::C},
      {"Fe2O3", k::Species::Fe2O3}, {"Fe3O4", k::Species::Fe3O4}, {"Al2O3", k::Species::Al2O3}};
  const auto it = table.find(name);
  return it == table.end() ? 0.0 : k::molarMass(it->second);
}

std::array<double, 3> vec(const v1::Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

void addChemistry(const v1::Configure& c, dem::DemConfig& cfg) {
  dem::ChemistryOptions& o = cfg.chemistry;
  for (const auto& r : c.reactions()) {
    dem::ReactionConfig d;
    d.name = r.name();
    for (const auto& t : r.terms())
      d.terms.push_back({t.species(), t.nu()});
    switch (r.rate().law()) {
    case v1::RATE_LAW_CONSTANT:
      d.law = dem::kernels::RateLaw::Constant;
      break;
    case v1::RATE_LAW_ARRHENIUS:
      d.law = dem::kernels::RateLaw::Arrhenius;
      break;
    default:
      COREDEM_CHECK(false,
                    "Configure: reaction '{}' has no rate law; use RATE_LAW_CONSTANT or "
                    "RATE_LAW_ARRHENIUS",
                    r.name());
    }
    d.A = r.rate().a();
    d.beta = r.rate().beta();
    d.E = r.rate().activation_energy();
    d.orderSpecies = r.rate().order_species();
    d.order = r.rate().order();
    d.heatFromNasa7 = r.heat_case() == v1::Reaction::kHeatFromNasa7 && r.heat_from_nasa7();
    d.heatOfReaction = r.heat_case() == v1::Reaction::kHeatOfReaction ? r.heat_of_reaction() : 0.0;
    o.reactions.push_back(std::move(d));
  }
  if (c.has_chemistry()) {
    const auto& ch = c.chemistry();
    const auto& clg = ch.clg();
    o.clg.charGasification = clg.char_gasification();
    COREDEM_CHECK(
        clg.char_stoichiometry() != v1::CHAR_STOICHIOMETRY_SEED,
        "Configure: chemistry.clg.char_stoichiometry = seed is not implemented (the seed's "
        "pseudo-char lines of R1 and R2 are not mutually consistent, docs/physics.md §6.1); use "
        "carbon");
    o.clg.ocReduction = clg.oc_reduction();
    o.clg.wgs = clg.wgs();
    switch (clg.wgs_equilibrium()) {
    case v1::WGS_EQUILIBRIUM_SEED:
      o.clg.wgsParams.equilibrium = dem::kernels::WgsEquilibrium::Seed;
      break;
    case v1::WGS_EQUILIBRIUM_THERMODYNAMIC:
      o.clg.wgsParams.equilibrium = dem::kernels::WgsEquilibrium::Thermodynamic;
      break;
    default:
      o.clg.wgsParams.equilibrium = dem::kernels::WgsEquilibrium::YoonDenn;
      break;
    }
    for (const auto& kv : clg.kinetics())
      dem::setClgKinetic(o.clg, kv.name(), kv.value());
    if (ch.has_removal_fraction())
      o.removalFraction = ch.removal_fraction();
    if (ch.has_reaction_heat())
      o.reactionHeat = ch.reaction_heat();
  }
  // Partial pressures use the gas pressure of the constant gas properties (Pa).
  if (c.gas().has_constant() && c.gas().constant().pressure() > 0.0) {
    o.pressure = c.gas().constant().pressure();
  }
}

/// The materials, addressed by id: each id's index in cfg.materials and its density.
struct MaterialIds {
  std::map<std::uint32_t, int> index;
  std::map<std::uint32_t, double> density;
};

MaterialIds addMaterials(const v1::Configure& c, dem::DemConfig& cfg) {
  MaterialIds ids;
  cfg.materials.clear();
  for (const auto& m : c.materials()) {
    COREDEM_CHECK(ids.index.count(m.id()) == 0, "Configure: material id {} appears twice", m.id());
    dem::Material d;
    d.name = m.name().empty() ? "material-" + std::to_string(m.id()) : m.name();
    d.kn = m.k_n();
    d.en = m.e_n();
    d.mu = m.friction();
    d.ktFactor = m.has_kt_factor() ? m.kt_factor() : 2.0 / 7.0;
    d.etatFactor = m.has_etat_factor() ? m.etat_factor() : 0.5;
    if (m.cp() > 0.0)
      d.cp = m.cp(); // 0 (unset): the default 840 J/kg/K, as in the case schema
    d.conductivity = m.conductivity();
    d.emissivity = m.emissivity();
    if (m.has_youngs_modulus()) // v1.6 (unset: not given, needed by hertz-mindlin only)
      d.youngsModulus = m.youngs_modulus();
    if (m.has_poisson_ratio())
      d.poissonRatio = m.poisson_ratio();
    ids.index[m.id()] = static_cast<int>(cfg.materials.size());
    ids.density[m.id()] = m.density();
    cfg.materials.push_back(d);
  }
  COREDEM_CHECK(!cfg.materials.empty(), "Configure: no materials; give at least one (k_n, e_n, "
                                        "friction, density)");
  return ids;
}

/// The index of material id `id` of a wall or a material pair (v1.6), named `what` in the error.
int materialIndexOf(const MaterialIds& materials, std::uint32_t id, const std::string& what) {
  const auto it = materials.index.find(id);
  COREDEM_CHECK(it != materials.index.end(),
                "Configure: {} uses material id {}, which is not among the materials", what, id);
  return it->second;
}

/// Solid species: v1.1 Configure.solid_species when given (chemistry); else the names used in
/// particle compositions, in order of first appearance. Returns their names.
std::vector<std::string> addSolidSpecies(const v1::Configure& c, dem::DemConfig& cfg) {
  std::vector<std::string> solid;
  for (const auto& s : c.solid_species()) {
    COREDEM_CHECK(std::find(solid.begin(), solid.end(), s.name()) == solid.end(),
                  "Configure: solid species '{}' appears twice", s.name());
    solid.push_back(s.name());
  }
  for (const auto& ps : c.particle_sets()) {
    if (c.solid_species_size() > 0) {
      for (const auto& nv : ps.composition()) {
        COREDEM_CHECK(
            std::find(solid.begin(), solid.end(), nv.name()) != solid.end(),
            "Configure: particle set '{}' has composition species '{}', which is not among "
            "the solid species",
            ps.name(), nv.name());
      }
      continue;
    }
    for (const auto& nv : ps.composition()) {
      if (std::find(solid.begin(), solid.end(), nv.name()) == solid.end()) {
        solid.push_back(nv.name());
      }
    }
  }
  for (const auto& name : solid) {
    double molar = 0.0;
    for (const auto& s : c.solid_species_size() > 0 ? c.solid_species() : c.species()) {
      if (s.name() == name) {
        molar = s.molar_mass();
      }
    }
    if (c.solid_species_size() == 0 && molar <= 0.0) {
      // Protocol v1.0 names composition species without molar masses (v1.1 adds
      // Configure.solid_species): the DEM core's species table gives them.
      molar = builtinMolarMass(name);
      COREDEM_CHECK(molar > 0.0,
                    "Configure: composition species '{}' has no molar mass: it is neither a gas "
                    "species nor one of CoReDEM's solid species (C, Fe2O3, Fe3O4, Al2O3); declare "
                    "it in Configure.solid_species (protocol v1.1)",
                    name);
    }
    cfg.solidSpecies.push_back({name, molar});
  }
  return solid;
}

/// Particle sets. With an initial state file the file's particles replace them after
/// construction (readState), but they are still built when given: the DEM core derives
/// dt_dem_max from the sets' materials and sizes.
void addParticleSets(const v1::Configure& c, const MaterialIds& materials,
                     const std::vector<std::string>& solid, dem::DemConfig& cfg) {
  int index = 0;
  for (const auto& ps : c.particle_sets()) {
    const auto it = materials.index.find(ps.material_id());
    COREDEM_CHECK(it != materials.index.end(),
                  "Configure: particle set {} ('{}') uses material "
                  "id {}, which is not among the materials",
                  index, ps.name(), ps.material_id());
    dem::ParticleSet d;
    d.name = ps.name().empty() ? "set-" + std::to_string(index) : ps.name();
    d.material = it->second;
    switch (ps.packing()) {
    case v1::PACKING_RANDOM:
      d.packing = dem::Packing::Random;
      break;
    case v1::PACKING_EXPLICIT:
      d.packing = dem::Packing::Explicit;
      COREDEM_CHECK(ps.positions_size() > 0 &&
                        static_cast<std::uint64_t>(ps.positions_size()) == ps.count(),
                    "Configure: particle set '{}' has explicit packing with {} positions but "
                    "count {}; give one position per particle",
                    d.name, ps.positions_size(), ps.count());
      for (const auto& p : ps.positions()) {
        d.positions.insert(d.positions.end(), {p.x(), p.y(), p.z()});
      }
      break;
    case v1::PACKING_LATTICE:
    case v1::PACKING_UNSPECIFIED:
      d.packing = dem::Packing::Lattice;
      break;
    default:
      COREDEM_CHECK(false,
                    "Configure: particle set '{}' has an unknown packing {}; use "
                    "LATTICE, RANDOM or EXPLICIT",
                    d.name, static_cast<int>(ps.packing()));
    }
    d.regionMin = vec(ps.region_min());
    d.regionMax = vec(ps.region_max());
    d.count = static_cast<std::size_t>(ps.count());
    d.diameter = ps.diameter();
    // The material's density when the set gives none (the id was found above).
    d.density = ps.density() > 0.0 ? ps.density() : materials.density.at(ps.material_id());
    d.temperature = ps.temperature() > 0.0 ? ps.temperature() : d.temperature;
    // No composition: left empty, the DEM core puts all of the mass in the first solid
    // species (docs/protocol.md §3).
    d.composition.assign(ps.composition().empty() ? 0 : solid.size(), 0.0);
    for (const auto& nv : ps.composition()) {
      const auto k = std::find(solid.begin(), solid.end(), nv.name()) - solid.begin();
      d.composition[static_cast<std::size_t>(k)] = nv.value();
    }
    d.velocity = vec(ps.initial_velocity());
    if (ps.seed() != 0) {
      d.seed = ps.seed();
    }
    cfg.particleSets.push_back(std::move(d));
    ++index;
  }
}

/// Revolved walls (v1.4: cylinders and cones; their geometry is checked when the system is
/// built).
void addRevolvedWalls(const v1::Configure& c, const MaterialIds& materials, dem::DemConfig& cfg) {
  for (int i = 0; i < c.walls().revolved_size(); ++i) {
    const auto& r = c.walls().revolved(i);
    dem::WallSide side = dem::WallSide::Inside;
    switch (r.side()) {
    case v1::WALL_SIDE_UNSPECIFIED:
    case v1::WALL_SIDE_INSIDE:
      break;
    case v1::WALL_SIDE_OUTSIDE:
      side = dem::WallSide::Outside;
      break;
    case v1::WALL_SIDE_BOTH:
      side = dem::WallSide::Both;
      break;
    default:
      COREDEM_CHECK(false,
                    "Configure: walls.revolved[{}] has an unknown side {}; use WALL_SIDE_INSIDE, "
                    "OUTSIDE or BOTH",
                    i, static_cast<int>(r.side()));
    }
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const double start = r.infinite() ? -kInf : r.start();
    const double end = r.infinite() ? kInf : r.end();
    cfg.walls.push_back(
        r.cone() ? dem::Wall::cone(vec(r.point()), vec(r.axis()), start, end, r.radius_start(),
                                   r.radius_end(), side, r.cap_start(), r.cap_end())
                 : dem::Wall::cylinder(vec(r.point()), vec(r.axis()), r.radius_start(), start, end,
                                       side, r.cap_start(), r.cap_end()));
    if (r.has_material_id()) // v1.6; unset: the particle's own
      cfg.walls.back().material =
          materialIndexOf(materials, r.material_id(), "walls.revolved[" + std::to_string(i) + "]");
  }
}

/// Material pairs (v1.6): e_n and friction of a pair of materials replacing the mixing.
void addMaterialPairs(const v1::Configure& c, const MaterialIds& materials, dem::DemConfig& cfg) {
  cfg.materialPairs.clear();
  for (int i = 0; i < c.material_pairs_size(); ++i) {
    const auto& p = c.material_pairs(i);
    const std::string what = "material_pairs[" + std::to_string(i) + "]";
    dem::MaterialPair d;
    d.a = materialIndexOf(materials, p.material_a(), what);
    d.b = materialIndexOf(materials, p.material_b(), what);
    if (p.has_e_n())
      d.en = p.e_n();
    if (p.has_friction())
      d.mu = p.friction();
    cfg.materialPairs.push_back(d);
  }
}

/// Walls: box, planes, revolved, meshes (each with its contact material, v1.6); the wall
/// temperature and material; gravity.
void addWalls(const v1::Configure& c, const MaterialIds& materials, dem::DemConfig& cfg) {
  // A wall's contact material (v1.6): unset, the particle's own (−1).
  auto wallMaterial = [&](bool has, std::uint32_t id, const std::string& what) {
    return has ? materialIndexOf(materials, id, what) : -1;
  };
  if (c.walls().has_box()) {
    const auto& b = c.walls().box();
    cfg.addBox(vec(b.min()), vec(b.max()));
    const int m = wallMaterial(b.has_material_id(), b.material_id(), "walls.box");
    for (std::size_t k = cfg.walls.size() - 6; k < cfg.walls.size(); ++k)
      cfg.walls[k].material = m;
  }
  for (int i = 0; i < c.walls().planes_size(); ++i) {
    const auto& p = c.walls().planes(i);
    cfg.walls.push_back(dem::Wall::plane(vec(p.point()), vec(p.normal())));
    cfg.walls.back().material = wallMaterial(p.has_material_id(), p.material_id(),
                                             "walls.planes[" + std::to_string(i) + "]");
  }
  addRevolvedWalls(c, materials, cfg);
  for (int i = 0; i < c.walls().meshes_size(); ++i) {
    const auto& m = c.walls().meshes(i);
    COREDEM_CHECK(m.vertices_size() % 3 == 0 && m.triangles_size() % 3 == 0,
                  "Configure: walls.meshes[{}] ('{}') has {} vertex values and {} index values; "
                  "give x,y,z triples and index triples",
                  i, m.name(), m.vertices_size(), m.triangles_size());
    dem::MeshWall d;
    d.name = m.name().empty() ? "mesh-" + std::to_string(i) : m.name();
    d.vertices.assign(m.vertices().begin(), m.vertices().end());
    d.triangles.assign(m.triangles().begin(), m.triangles().end());
    if (m.has_material_id()) // v1.6; unset: the particle's own
      d.material =
          materialIndexOf(materials, m.material_id(), "walls.meshes[" + std::to_string(i) + "]");
    cfg.meshes.push_back(std::move(d));
  }
  cfg.wallTemperature = c.walls().temperature(); // 0 = adiabatic (docs/heat-coupling.md "Walls")
  if (c.walls().temperature() > 0.0) {
    const auto wm = materials.index.find(c.walls().material_id());
    COREDEM_CHECK(wm != materials.index.end(),
                  "Configure: walls use material id {}, which is not "
                  "among the materials",
                  c.walls().material_id());
    cfg.wallMaterial = wm->second;
  }
  cfg.gravity = vec(c.gravity());
}

/// The coupling grid.
void addGrid(const v1::Configure& c, dem::DemConfig& cfg) {
  if (c.coupling_mesh().has_cartesian()) {
    const auto& g = c.coupling_mesh().cartesian();
    cfg.grid.origin = vec(g.origin());
    cfg.grid.spacing = vec(g.spacing());
    COREDEM_CHECK(g.counts().x() < (1u << 30) && g.counts().y() < (1u << 30) &&
                      g.counts().z() < (1u << 30),
                  "Configure: coupling grid counts {} x {} x {} are too large", g.counts().x(),
                  g.counts().y(), g.counts().z());
    cfg.grid.counts = {static_cast<int>(g.counts().x()), static_cast<int>(g.counts().y()),
                       static_cast<int>(g.counts().z())};
  }
}

} // namespace

dem::DemConfig toDemConfig(const v1::Configure& c, std::vector<std::string>* warnings) {
  dem::DemConfig cfg;
  const MaterialIds materials = addMaterials(c, cfg);
  // Gas species (Y_g / R_species columns).
  for (const auto& s : c.species()) {
    cfg.gasSpecies.push_back({s.name(), s.molar_mass()});
  }
  const std::vector<std::string> solid = addSolidSpecies(c, cfg);
  addParticleSets(c, materials, solid, cfg);
  addWalls(c, materials, cfg);
  addMaterialPairs(c, materials, cfg);
  addGrid(c, cfg);

  // Chemistry (v1.1): reactions, CLG models, removal, reaction heat (docs/thermochemistry.md).
  addChemistry(c, cfg);

  // Model options by name (`models:` in case.yaml), through the model registry (models.h).
  for (const auto& kv : c.options()) {
    if (kv.key() == protocol::fields::kCouplingSchemeOption ||
        kv.key() == protocol::fields::kInitialStateOption) {
      continue; // the server's own options (session_setup.cpp), not DEM models
    }
    if (!dem::applyModelOption(cfg, kv.key(), kv.value()) && warnings != nullptr) {
      warnings->push_back(kv.key());
    }
  }
  return cfg;
}

} // namespace coredem::server
