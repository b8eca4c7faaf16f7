// Configure of a run, built from the case (configure.h).
#include "configure.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <coredem/common/check.h>
#include <coredem/dem/dem_config.h>
#include <coredem/dem/models.h>
#include <coredem/protocol/coupling_scheme.h>
#include <coredem/protocol/initial_state.h>

namespace fs = std::filesystem;
namespace v1 = coredem::v1;

namespace coredem::orchestrator {
namespace {

v1::Vec3 vec(const Vec3& v) {
  v1::Vec3 out;
  out.set_x(v[0]);
  out.set_y(v[1]);
  out.set_z(v[2]);
  return out;
}

/// Configure.options: the `models:` choices by name, and the server's own options: the coupling
/// scheme (sequential sends nothing: its Configure stays as before) and, for a case.yaml
/// `initial_state`, a new start from another run's particles (protocol/initial_state.h).
void addOptions(const CaseConfig& c, v1::Configure& cfg) {
  const auto add = [&](std::string key, std::string value) {
    auto* kv = cfg.add_options();
    kv->set_key(std::move(key));
    kv->set_value(std::move(value));
  };
  for (const auto& [k, v] : c.models) {
    add(k, v);
  }
  if (c.coupling.staggered()) {
    add(std::string(protocol::fields::kCouplingSchemeOption), "staggered");
  }
  if (!c.initialState.empty()) {
    add(std::string(protocol::fields::kInitialStateOption),
        std::string(protocol::fields::kInitialStateStart));
  }
}

} // namespace

v1::Configure buildConfigure(const CaseConfig& c, const fs::path& runDir, double dtCfd,
                             const SubcyclePlan& plan) {
  v1::Configure cfg;
  cfg.set_case_name(c.name);
  auto* grid = cfg.mutable_coupling_mesh()->mutable_cartesian();
  *grid->mutable_origin() = vec(c.grid.origin);
  *grid->mutable_spacing() = vec(c.grid.spacing);
  grid->mutable_counts()->set_x(c.grid.cells[0]);
  grid->mutable_counts()->set_y(c.grid.cells[1]);
  grid->mutable_counts()->set_z(c.grid.cells[2]);
  for (const auto& s : c.species) {
    auto* sp = cfg.add_species();
    sp->set_name(s.name);
    sp->set_molar_mass(s.molarMass);
  }
  auto* gas = cfg.mutable_gas()->mutable_constant();
  gas->set_density(c.gasProperties.density);
  gas->set_viscosity(c.gasProperties.viscosity);
  gas->set_conductivity(c.gasProperties.conductivity);
  gas->set_cp(c.gasProperties.cp);
  gas->set_temperature(c.gasProperties.temperature);
  gas->set_pressure(c.gasProperties.pressure);
  for (std::size_t i = 0; i < c.materials.size(); ++i) {
    const auto& m = c.materials[i];
    auto* mat = cfg.add_materials();
    mat->set_id(std::uint32_t(i));
    mat->set_name(m.name);
    mat->set_density(m.density);
    mat->set_k_n(m.kN);
    mat->set_e_n(m.eN);
    mat->set_friction(m.friction);
    if (m.ktFactor) {
      mat->set_kt_factor(*m.ktFactor);
    }
    if (m.etatFactor) {
      mat->set_etat_factor(*m.etatFactor);
    }
    mat->set_cp(m.cp);
    mat->set_conductivity(m.conductivity);
    mat->set_emissivity(m.emissivity);
    if (m.youngsModulus) { // v1.6
      mat->set_youngs_modulus(*m.youngsModulus);
    }
    if (m.poissonRatio) {
      mat->set_poisson_ratio(*m.poissonRatio);
    }
  }
  for (const auto& p : c.materialPairs) { // v1.6
    auto* mp = cfg.add_material_pairs();
    mp->set_material_a(std::uint32_t(materialIndex(c, p.a)));
    mp->set_material_b(std::uint32_t(materialIndex(c, p.b)));
    if (p.eN) {
      mp->set_e_n(*p.eN);
    }
    if (p.friction) {
      mp->set_friction(*p.friction);
    }
  }
  for (const auto& p : c.particles) {
    auto* ps = cfg.add_particle_sets();
    ps->set_name(p.name);
    ps->set_material_id(std::uint32_t(materialIndex(c, p.material)));
    ps->set_count(p.count);
    ps->set_diameter(p.diameter);
    ps->set_density(p.density);
    ps->set_temperature(p.temperature);
    for (const auto& [name, f] : p.composition) {
      protocol::addNamedValue(ps->mutable_composition(), name, f);
    }
    ps->set_packing(p.packing == "random" ? v1::PACKING_RANDOM : v1::PACKING_LATTICE);
    if (!p.positions.empty()) { // explicit packing (time.dt_dem / positions: docs/case-schema.md)
      ps->set_packing(v1::PACKING_EXPLICIT);
      for (const auto& x : p.positions) {
        *ps->add_positions() = vec(x);
      }
    }
    *ps->mutable_region_min() = vec(p.regionMin);
    *ps->mutable_region_max() = vec(p.regionMax);
    ps->set_seed(p.seed);
    *ps->mutable_initial_velocity() = vec(p.velocity);
  }
  auto* walls = cfg.mutable_walls();
  // v1.6: a wall's contact material when it names one (unset: each particle's own).
  const auto wallMaterial = [&](const std::string& name, auto* w) {
    if (!name.empty()) {
      w->set_material_id(std::uint32_t(materialIndex(c, name)));
    }
  };
  if (c.walls.box) {
    *walls->mutable_box()->mutable_min() = vec(c.walls.box->first);
    *walls->mutable_box()->mutable_max() = vec(c.walls.box->second);
    wallMaterial(c.walls.boxMaterial, walls->mutable_box());
  }
  for (const auto& pl : c.walls.planes) {
    auto* p = walls->add_planes();
    *p->mutable_point() = vec(pl.point);
    *p->mutable_normal() = vec(pl.normal);
    wallMaterial(pl.material, p);
  }
  // v1.4: cylinders and cones, triangle meshes (the session refuses a server below 1.4 first).
  for (const auto& r : c.walls.revolved) {
    auto* w = walls->add_revolved();
    *w->mutable_point() = vec(r.point);
    *w->mutable_axis() = vec(r.axis);
    w->set_cone(r.cone);
    w->set_radius_start(r.radiusFrom);
    w->set_radius_end(r.radiusTo);
    w->set_infinite(!r.finite);
    if (r.finite) {
      w->set_start(r.from);
      w->set_end(r.to);
    }
    w->set_side(r.side == "outside"
                    ? v1::WALL_SIDE_OUTSIDE
                    : (r.side == "both" ? v1::WALL_SIDE_BOTH : v1::WALL_SIDE_INSIDE));
    w->set_cap_start(r.capStart);
    w->set_cap_end(r.capEnd);
    wallMaterial(r.material, w);
  }
  for (const auto& m : c.walls.meshes) {
    auto* w = walls->add_meshes();
    w->set_name(m.name); // from case.yaml: part of the DEM's config hash, stable across restarts
    w->mutable_vertices()->Add(m.vertices.begin(), m.vertices.end());
    w->mutable_triangles()->Add(m.triangles.begin(), m.triangles.end());
    wallMaterial(m.material, w);
  }
  walls->set_material_id(std::uint32_t(std::max(0, materialIndex(c, c.walls.material))));
  walls->set_temperature(c.walls.temperature);
  *cfg.mutable_gravity() = vec(c.gravity);
  if (!c.initialState.empty()) {
    cfg.set_initial_state_file(c.initialState.string());
  }
  cfg.mutable_sub_cycling()->set_dt_cfd(dtCfd);
  cfg.mutable_sub_cycling()->set_n_sub(std::uint32_t(plan.nSub));
  cfg.mutable_sub_cycling()->set_dt_dem(plan.dtDem);
  addOptions(c, cfg);
  cfg.set_output_directory(fs::absolute(runDir).string());
  addChemistryToConfigure(c, cfg); // v1.1: solid species, reactions, chemistry
  return cfg;
}

std::string demVersionRefusal(const CaseConfig& c, std::uint32_t agreedMajor,
                              std::uint32_t agreedMinor) {
  // Chemistry travels in Configure fields of protocol v1.1, which a v1.0 server would ignore.
  if (c.usesChemistry() && agreedMinor < 1) {
    return fmt::format("the DEM server speaks protocol {}.{}, but this case uses chemistry "
                       "(solid_species, reactions or chemistry), which needs protocol 1.1; use a "
                       "coredem-dem built from this release",
                       agreedMajor, agreedMinor);
  }
  // Cylinders, cones and meshes travel in Walls fields of v1.4: an older server would run
  // without those walls and let the particles fall through them.
  if (c.usesWallShapes() && agreedMinor < protocol::kMinorWallShapes) {
    std::string what;
    const auto add = [&](const std::string& item) { what += (what.empty() ? "" : ", ") + item; };
    std::size_t cylinders = 0, cones = 0;
    for (const auto& r : c.walls.revolved) {
      ++(r.cone ? cones : cylinders);
    }
    if (cylinders > 0) {
      add(fmt::format("{} in walls.cylinders", cylinders));
    }
    if (cones > 0) {
      add(fmt::format("{} in walls.cones", cones));
    }
    if (!c.walls.meshes.empty()) {
      add(fmt::format("{} in walls.meshes", c.walls.meshes.size()));
    }
    return fmt::format("the DEM server speaks protocol {}.{}, but this case has cylinder, cone or "
                       "mesh walls ({}), which need protocol 1.{} (this coredem speaks {}); an "
                       "older server would ignore them and the particles would pass through. Use "
                       "a coredem-dem built from this release, or give the walls as walls.box and "
                       "walls.planes",
                       agreedMajor, agreedMinor, what, protocol::kMinorWallShapes,
                       protocol::kProtocolVersion.toString());
  }
  // Material pairs, wall materials and the Hertz–Mindlin properties travel in fields of v1.6:
  // an older server would run with the mixed properties instead.
  const std::string contact = c.contactMaterialsUsed();
  if (!contact.empty() && agreedMinor < protocol::kMinorContactMaterials) {
    return fmt::format("the DEM server speaks protocol {}.{}, but this case uses contact "
                       "materials ({}), which need protocol 1.{} (this coredem speaks {}); an "
                       "older server would ignore them. Use a coredem-dem built from this release",
                       agreedMajor, agreedMinor, contact, protocol::kMinorContactMaterials,
                       protocol::kProtocolVersion.toString());
  }
  return {};
}

std::string configureSizeRefusal(const v1::Configure& configure, std::int64_t maxBytes) {
  const auto bytes = static_cast<std::int64_t>(configure.ByteSizeLong());
  // The envelope around the body and the server's allowance of 4 KiB for it are left as slack.
  if (maxBytes <= 0 || bytes <= maxBytes) {
    return {};
  }
  std::uint64_t triangles = 0;
  for (const auto& m : configure.walls().meshes()) {
    triangles += std::uint64_t(m.triangles_size()) / 3;
  }
  return fmt::format("the Configure message is {:.1f} MiB ({} triangles in walls.meshes), more "
                     "than the DEM server's message limit of {:.0f} MiB (coredem-dem "
                     "--max-message-mb), which would close the connection without a reply; "
                     "coarsen the mesh walls (about 24 bytes per triangle of a welded mesh) or "
                     "start coredem-dem with a larger --max-message-mb and give it as dem.endpoint",
                     double(bytes) / 1048576.0, triangles, double(maxBytes) / 1048576.0);
}

std::string couplingSchemeMismatch(const CaseConfig& c, const v1::StepDone& demDone,
                                   std::int64_t step) {
  const auto lag =
      protocol::findNamedValue(demDone.diagnostics(), protocol::fields::kCouplingLagDiagnostic);
  const bool demStaggered = lag && *lag == 1.0;
  if (demStaggered == c.coupling.staggered()) {
    return {};
  }
  if (c.coupling.staggered()) {
    return fmt::format("does not run the staggered coupling scheme (coupling: {{scheme: "
                       "staggered}}): its StepDone of step {} reports no {} = 1, as a server "
                       "that ignores the Configure option {} (older than this coredem) would; use "
                       "a coredem-dem of this version or the sequential scheme",
                       step, protocol::fields::kCouplingLagDiagnostic,
                       protocol::fields::kCouplingSchemeOption);
  }
  return fmt::format("reports {} in step {} of a sequential run",
                     protocol::fields::kCouplingLagDiagnostic, step);
}

} // namespace coredem::orchestrator
