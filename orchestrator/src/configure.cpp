// Configure of a run, built from the case (configure.h).
#include "configure.h"

#include <cmath>
#include <limits>
#include <numbers>

#include <coredem/protocol/coupling_scheme.h>

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

} // namespace

double estimateDtDemMax(const CaseConfig& c) {
  double tMin = std::numeric_limits<double>::infinity();
  for (const auto& p : c.particles) {
    const auto& m = c.materials[std::size_t(materialIndex(c, p.material))];
    const double rho = p.density > 0 ? p.density : m.density;
    const double mass = rho * std::numbers::pi * std::pow(p.diameter, 3) / 6.0;
    const double le = std::log(m.eN);
    const double t =
        std::sqrt(std::numbers::pi * std::numbers::pi + le * le) / std::sqrt(m.kN / (0.5 * mass));
    tMin = std::min(tMin, t);
  }
  return std::isfinite(tMin) ? tMin / 50.0 : c.dt.dt;
}

SubcyclePlan planFor(const CaseConfig& c, double dt, double dtDemMax) {
  if (c.dtDem > 0.0) {
    const double ratio = dt / c.dtDem;
    double n = std::round(ratio);
    if (n < 1.0 || std::abs(ratio - n) > 1e-9 * n) {
      n = std::max(1.0, std::ceil(ratio));
    }
    return SubcyclePlan{std::int64_t(n), dt / n};
  }
  return planSubcycles(dt, dtDemMax);
}

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
  if (c.walls.box) {
    *walls->mutable_box()->mutable_min() = vec(c.walls.box->first);
    *walls->mutable_box()->mutable_max() = vec(c.walls.box->second);
  }
  for (const auto& pl : c.walls.planes) {
    auto* p = walls->add_planes();
    *p->mutable_point() = vec(pl.point);
    *p->mutable_normal() = vec(pl.normal);
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
  for (const auto& [k, v] : c.models) {
    auto* kv = cfg.add_options();
    kv->set_key(k);
    kv->set_value(v);
  }
  if (c.coupling.staggered()) { // sequential sends nothing: its Configure stays as before
    auto* kv = cfg.add_options();
    kv->set_key(std::string(protocol::fields::kCouplingSchemeOption));
    kv->set_value("staggered");
  }
  cfg.set_output_directory(fs::absolute(runDir).string());
  addChemistryToConfigure(c, cfg); // v1.1: solid species, reactions, chemistry
  return cfg;
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
