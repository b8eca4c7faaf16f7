// coredem-golden-gen DIR [MINOR]: writes one golden multipart message per message type of
// protocol v1.MINOR (default 0) into DIR (protocol/golden/v1.0, protocol/golden/v1.1). The
// messages of v1.1 are those of v1.0 plus the v1.1 fields (Welcome agreed minor 1; Configure
// with an explicitly placed particle set, the frozen-motion option, solid species, a reaction
// and the chemistry switches). The files are committed and never regenerated for a
// released version: tests/unit/protocol/golden_test.cpp decodes them with the current code
// forever and checks every value written below. Container format: multipart_file.h.
// v1.2 (MINOR 2): the v1.1 messages with minor 2 in Hello/Welcome/Reject, the Hello of rank 1 of
// a 2-rank decomposed CFD participant, and the GasFields and Sources partial (one rank's
// contributions for the coupling cell it touches, docs/protocol.md "Decomposed CFD").
// v1.3 (MINOR 3): the v1.2 messages with minor 3 in Hello/Welcome/Reject and the partial Sources
// also carrying Q_rad (the radiation heat the particles gave the gas) for its one cell.
// v1.4 (MINOR 4): the v1.3 messages with minor 4 in Hello/Welcome/Reject and a Configure whose
// walls also hold a capped cylinder, a cone and a two-triangle mesh (walls.revolved, .meshes).
// v1.5 (MINOR 5): the v1.4 messages with minor 5 in Hello/Welcome/Reject, the partial GasFields
// also carrying Q_split (heat for the cell's particles, J/m3, extensive) and the partial Sources
// also carrying mom_p (momentum of the released mass, N/m3) for its one cell.
// v1.6 (MINOR 6): the v1.5 messages with minor 6 in Hello/Welcome/Reject and a Configure whose
// material also has Young's modulus and Poisson's ratio, with a second material, a material pair
// and contact materials on the box, the plane, the cylinder and the mesh (the cone without one).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <utility>

#include <coredem/protocol/fields.h>
#include <coredem/protocol/message.h>
#include <coredem/protocol/multipart_file.h>

using namespace coredem::protocol;
namespace v1 = coredem::v1;

namespace {

constexpr std::uint64_t kCells = 2;   // a 2 x 1 x 1 grid
constexpr std::uint32_t kSpecies = 2; // O2, N2
constexpr std::uint64_t kTouched = 1; // v1.2 partial messages: one coupling cell (index 1)

/// Array values of the golden GasFields/Sources: field f (index in fields.h order), flat
/// index i -> 0.25 * (f + 1) + 0.125 * i (exact in binary).
double goldenValue(std::size_t f, std::size_t i) {
  return 0.25 * double(f + 1) + 0.125 * double(i);
}

void stamp(Message& m, std::uint64_t seq) {
  m.setSessionId("golden-session").setSequence(seq).setStep(3).setTime(0.25);
  m.envelope().set_sender("coredem-golden-gen 1.0");
}

v1::Configure goldenConfigure() {
  v1::Configure c;
  c.set_case_name("golden");
  auto* g = c.mutable_coupling_mesh()->mutable_cartesian();
  g->mutable_origin()->set_x(-0.5);
  g->mutable_origin()->set_y(0.0);
  g->mutable_origin()->set_z(0.25);
  g->mutable_spacing()->set_x(0.5);
  g->mutable_spacing()->set_y(1.0);
  g->mutable_spacing()->set_z(2.0);
  g->mutable_counts()->set_x(2);
  g->mutable_counts()->set_y(1);
  g->mutable_counts()->set_z(1);
  auto* o2 = c.add_species();
  o2->set_name("O2");
  o2->set_molar_mass(0.032);
  auto* n2 = c.add_species();
  n2->set_name("N2");
  n2->set_molar_mass(0.028);
  auto* gas = c.mutable_gas()->mutable_constant();
  gas->set_density(1.2);
  gas->set_viscosity(1.8e-5);
  gas->set_conductivity(0.026);
  gas->set_cp(1005.0);
  gas->set_temperature(300.0);
  gas->set_pressure(101325.0);
  auto* p = c.add_particle_sets();
  p->set_material_id(1);
  p->set_count(100);
  p->set_diameter(1e-3);
  p->set_density(0.0);
  p->set_temperature(1073.15);
  auto* fe = p->add_composition();
  fe->set_name("Fe2O3");
  fe->set_value(0.6);
  auto* al = p->add_composition();
  al->set_name("Al2O3");
  al->set_value(0.4);
  p->set_packing(v1::PACKING_RANDOM);
  p->mutable_region_min()->set_x(-0.5);
  p->mutable_region_max()->set_x(0.5);
  p->mutable_region_max()->set_y(1.0);
  p->mutable_region_min()->set_z(0.25);
  p->mutable_region_max()->set_z(2.25);
  p->set_seed(42);
  p->mutable_initial_velocity()->set_z(-0.5);
  p->set_name("carrier");
  auto* m = c.add_materials();
  m->set_id(1);
  m->set_name("ilmenite");
  m->set_density(4200.0);
  m->set_k_n(1000.0);
  m->set_e_n(0.9);
  m->set_friction(0.3);
  m->set_kt_factor(0.25); // explicit; etat_factor left unset (default 1/2)
  m->set_cp(850.0);
  m->set_conductivity(2.5);
  m->set_emissivity(0.8);
  auto* w = c.mutable_walls();
  w->mutable_box()->mutable_min()->set_x(-0.5);
  w->mutable_box()->mutable_max()->set_x(0.5);
  w->mutable_box()->mutable_max()->set_y(1.0);
  w->mutable_box()->mutable_min()->set_z(0.25);
  w->mutable_box()->mutable_max()->set_z(2.25);
  auto* plane = w->add_planes();
  plane->mutable_point()->set_z(0.25);
  plane->mutable_normal()->set_z(1.0);
  w->set_material_id(1);
  w->set_temperature(0.0);
  c.mutable_gravity()->set_z(-9.81);
  c.mutable_sub_cycling()->set_dt_cfd(1e-4);
  c.mutable_sub_cycling()->set_n_sub(50);
  c.mutable_sub_cycling()->set_dt_dem(2e-6);
  c.set_start_step(3);
  c.set_start_time(0.25);
  auto* opt = c.add_options();
  opt->set_key("drag");
  opt->set_value("gidaspow");
  c.set_output_directory("out");
  return c;
}

/// v1.1 additions to the golden Configure (tests/unit/protocol/golden_v1_1_test.cpp checks them).
void addV11(v1::Configure& c) {
  // Verification-case additions: explicit positions, frozen motion (options), forced dt_dem.
  auto* p = c.add_particle_sets();
  p->set_material_id(1);
  p->set_count(2);
  p->set_diameter(3e-3);
  p->set_temperature(298.15);
  p->set_packing(v1::PACKING_EXPLICIT);
  auto* a = p->add_positions();
  a->set_x(0.25);
  a->set_y(0.5);
  a->set_z(1.0);
  auto* b = p->add_positions();
  b->set_x(-0.25);
  b->set_y(0.5);
  b->set_z(1.0);
  p->set_name("placed");
  auto* opt = c.add_options();
  opt->set_key("motion");
  opt->set_value("frozen");
  // Chemistry.
  for (auto [name, molar] :
       {std::pair{"Fe2O3", 0.159688}, {"Fe3O4", 0.231533}, {"Al2O3", 0.101961}}) {
    auto* s = c.add_solid_species();
    s->set_name(name);
    s->set_molar_mass(molar);
  }
  auto* r = c.add_reactions();
  r->set_name("oxidation");
  for (auto [sp, nu] : {std::pair{"Fe3O4", -4.0}, {"O2", -1.0}, {"Fe2O3", 6.0}}) {
    auto* t = r->add_terms();
    t->set_species(sp);
    t->set_nu(nu);
  }
  r->mutable_rate()->set_law(v1::RATE_LAW_ARRHENIUS);
  r->mutable_rate()->set_a(2.5e-3);
  r->mutable_rate()->set_beta(0.5);
  r->mutable_rate()->set_activation_energy(8.0e4);
  r->mutable_rate()->set_order_species("O2");
  r->mutable_rate()->set_order(1.0);
  r->set_heat_of_reaction(-4.75e5);
  auto* ch = c.mutable_chemistry();
  ch->mutable_clg()->set_char_gasification(false);
  ch->mutable_clg()->set_oc_reduction(true);
  ch->mutable_clg()->set_wgs(true);
  ch->mutable_clg()->set_wgs_equilibrium(v1::WGS_EQUILIBRIUM_THERMODYNAMIC);
  ch->mutable_clg()->set_char_stoichiometry(v1::CHAR_STOICHIOMETRY_CARBON);
  addNamedValue(ch->mutable_clg()->mutable_kinetics(), "k0_H2", 1.5e-3);
  ch->set_removal_fraction(0.125);
  ch->set_reaction_heat(false);
}

/// v1.4 additions to the golden Configure (tests/unit/protocol/golden_v1_4_test.cpp checks them):
/// a cylinder, a cone and a mesh wall.
void addV14(v1::Configure& c) {
  auto* w = c.mutable_walls();
  auto* cyl = w->add_revolved();
  cyl->mutable_point()->set_y(0.5);
  cyl->mutable_point()->set_z(0.25);
  cyl->mutable_axis()->set_z(1.0);
  cyl->set_radius_start(0.5);
  cyl->set_radius_end(0.5);
  cyl->set_start(0.0);
  cyl->set_end(2.0);
  cyl->set_side(v1::WALL_SIDE_INSIDE);
  cyl->set_cap_start(true);
  auto* cone = w->add_revolved();
  cone->set_cone(true);
  cone->mutable_point()->set_y(0.5);
  cone->mutable_point()->set_z(0.25);
  cone->mutable_axis()->set_z(2.0); // need not be unit length
  cone->set_radius_start(0.125);
  cone->set_radius_end(0.375);
  cone->set_start(0.5);
  cone->set_end(1.5);
  cone->set_side(v1::WALL_SIDE_OUTSIDE);
  cone->set_cap_end(true);
  auto* mesh = w->add_meshes();
  mesh->set_name("plate.stl");
  for (double v : {-0.5, 0.0, 1.0, 0.5, 0.0, 1.0, 0.5, 1.0, 1.0, -0.5, 1.0, 1.0}) {
    mesh->add_vertices(v);
  }
  for (int i : {0, 1, 2, 0, 2, 3}) {
    mesh->add_triangles(i);
  }
}

/// v1.6 additions to the golden Configure (tests/unit/protocol/golden_v1_6_test.cpp checks
/// them): the Hertz–Mindlin properties, a second material, a material pair, wall materials.
void addV16(v1::Configure& c) {
  c.mutable_materials(0)->set_youngs_modulus(1.5e8);
  c.mutable_materials(0)->set_poisson_ratio(0.25);
  auto* steel = c.add_materials();
  steel->set_id(2);
  steel->set_name("steel");
  steel->set_density(7800.0);
  steel->set_k_n(4000.0);
  steel->set_e_n(0.8);
  steel->set_friction(0.0);
  steel->set_youngs_modulus(2e11); // poisson_ratio left unset (default 0.3)
  auto* pair = c.add_material_pairs();
  pair->set_material_a(1);
  pair->set_material_b(2);
  pair->set_e_n(0.5); // friction left unset (the mixed value)
  auto* w = c.mutable_walls();
  w->mutable_box()->set_material_id(2);
  w->mutable_planes(0)->set_material_id(1);
  w->mutable_revolved(0)->set_material_id(2);
  w->mutable_meshes(0)->set_material_id(1);
}

void addFieldArrays(Message& m, std::span<const fields::FieldSpec> specs,
                    std::uint64_t rows = kCells) {
  std::size_t f = 0;
  for (const auto& spec : specs) {
    std::vector<double> v(rows * fields::componentsOf(spec.extent, kSpecies));
    for (std::size_t i = 0; i < v.size(); ++i) {
      v[i] = goldenValue(f, i);
    }
    m.addArray<double>(spec.name, v, fields::shapeOf(spec.extent, rows, kSpecies));
    ++f;
  }
}

using Golden = std::vector<std::pair<std::string, Message>>;

/// Hello, Welcome, Reject, Configure and Configured of protocol 1.minor.
void addSessionMessages(Golden& all, int minor) {
  {
    v1::FieldManifestEntry e;
    e.set_name("u_g");
    e.set_dtype(v1::DTYPE_FLOAT64);
    e.set_extent(v1::EXTENT_VECTOR3);
    e.set_direction(v1::FIELD_DIRECTION_SENDS);
    e.set_unit("m/s");
    Message m = makeHello(v1::ROLE_CFD, "coredem-gas 0.1.0", {"gas_fields", "checkpoint"}, {e});
    m.envelope().mutable_hello()->set_protocol_minor(std::uint32_t(minor));
    if (minor >= 2) { // rank 1 of a decomposed CFD participant on 2 ranks
      m.envelope().mutable_hello()->set_rank(1);
      m.envelope().mutable_hello()->set_rank_count(2);
    }
    m.setSessionId("").setSequence(1).setStep(0).setTime(0.0);
    all.emplace_back("hello", std::move(m));
  }
  {
    Message m =
        makeWelcome(v1::ROLE_DEM, "coredem-dem 0.1.0", 1, std::uint32_t(minor), "golden-session");
    m.envelope().mutable_welcome()->add_capabilities("cpu");
    stamp(m, 1);
    all.emplace_back("welcome", std::move(m));
  }
  {
    Message m = makeReject(v1::ERROR_CODE_VERSION, "protocol 1.0 vs 2.3");
    m.envelope().mutable_reject()->set_server_protocol_minor(std::uint32_t(minor));
    stamp(m, 1);
    all.emplace_back("reject", std::move(m));
  }
  {
    v1::Configure c = goldenConfigure();
    if (minor >= 1) {
      addV11(c);
    }
    if (minor >= 4) {
      addV14(c);
    }
    if (minor >= 6) {
      addV16(c);
    }
    Message m = makeConfigure(c);
    stamp(m, 2);
    all.emplace_back("configure", std::move(m));
  }
  {
    Message m = makeConfigured(2, 100, 2, 50, 2e-6);
    stamp(m, 2);
    all.emplace_back("configured", std::move(m));
  }
}

/// GasFields and Sources of protocol 1.minor (partial from 1.2, with Q_rad from 1.3, with Q_split
/// and mom_p from 1.5).
void addExchangeMessages(Golden& all, int minor) {
  {
    Message m = makeGasFields(3, 0.25, 1e-4, kCells, kSpecies);
    stamp(m, 3);
    if (minor >= 2) {
      // Partial: the rank touches coupling cell 1 only, with 0.125 m3 of its 0.5 m3 fluid.
      m.envelope().mutable_gas_fields()->set_partial(true);
      m.envelope().mutable_gas_fields()->set_touched_count(kTouched);
      m.addArray<std::int64_t>(fields::kTouchedCells, std::vector<std::int64_t>{1}, {kTouched});
      m.addArray<double>(fields::kFluidVolume, std::vector<double>{0.125}, {kTouched});
      addFieldArrays(m, fields::gasFields(), kTouched);
      if (minor >= 5) { // v1.5: heat for the cell's particles, J/m3 (field index 8; negative)
        m.addArray<double>(fields::kHeatToParticles, std::vector<double>{-goldenValue(8, 0)},
                           fields::shapeOf(fields::kHeatToParticles, kTouched, kSpecies));
      }
    } else {
      addFieldArrays(m, fields::gasFields());
    }
    all.emplace_back("gas_fields", std::move(m));
  }
  {
    Message m = makeSources(3, 0.25, 1e-4, kCells, kSpecies, 50);
    auto* l = m.envelope().mutable_sources()->mutable_ledger();
    addNamedValue(l->mutable_mass(), "particles", 0.0132);
    addNamedValue(l->mutable_energy(), "particles", 5.5e3);
    addNamedValue(l->mutable_species(), "O2", -1.5e-6);
    stamp(m, 3);
    if (minor >= 2) { // the answer to the partial GasFields: coupling cell 1 only
      m.envelope().mutable_sources()->set_partial(true);
      m.envelope().mutable_sources()->set_touched_count(kTouched);
      m.addArray<std::int64_t>(fields::kTouchedCells, std::vector<std::int64_t>{1}, {kTouched});
      addFieldArrays(m, fields::sourceFields(), kTouched);
      if (minor >= 3) { // v1.3: the radiation heat to the gas, W/m3 (field index 7)
        m.addArray<double>(fields::kRadiationHeat, std::vector<double>{goldenValue(7, 0)},
                           fields::shapeOf(fields::kRadiationHeat, kTouched, kSpecies));
      }
      if (minor >= 5) { // v1.5: the momentum of the released mass, N/m3 (field index 8)
        m.addArray<double>(
            fields::kReleasedMomentum,
            std::vector<double>{goldenValue(8, 0), goldenValue(8, 1), goldenValue(8, 2)},
            fields::shapeOf(fields::kReleasedMomentum, kTouched, kSpecies));
      }
    } else {
      addFieldArrays(m, fields::sourceFields());
    }
    all.emplace_back("sources", std::move(m));
  }
}

/// StepGrant, StepDone, the checkpoint messages, Heartbeat, Error, Shutdown and Ack.
void addControlMessages(Golden& all) {
  {
    Message m = makeStepGrant(3, 0.25, 1e-4, 50, 2e-6);
    stamp(m, 4);
    all.emplace_back("step_grant", std::move(m));
  }
  {
    v1::StepDone d;
    d.set_cfl(0.35);
    d.set_max_dt(2e-4);
    d.set_wall_seconds(0.125);
    addNamedValue(d.mutable_ledger()->mutable_mass(), "gas_in", 1.5);
    addNamedValue(d.mutable_ledger()->mutable_energy(), "gas_in", 300.0);
    addNamedValue(d.mutable_ledger()->mutable_species(), "CO2", 2.5e-3);
    addNamedValue(d.mutable_diagnostics(), "mean_T_p", 1050.5);
    Message m = makeStepDone(3, 0.25, d);
    stamp(m, 4);
    all.emplace_back("step_done", std::move(m));
  }
  {
    Message m = makeCheckpointRequest(3, "checkpoints/3", "periodic");
    stamp(m, 5);
    all.emplace_back("checkpoint_request", std::move(m));
  }
  {
    Message m = makeCheckpointDone(3, "checkpoints/3", {"dem.h5", "dem.json"});
    stamp(m, 5);
    all.emplace_back("checkpoint_done", std::move(m));
  }
  {
    Message m = makeHeartbeat("stepping");
    m.envelope().mutable_heartbeat()->set_unix_time(1.75e9);
    stamp(m, 6);
    all.emplace_back("heartbeat", std::move(m));
  }
  {
    Message m = makeError(v1::ERROR_CODE_NON_FINITE, "array 'T_g' contains NaN at flat index 1", 3,
                          v1::MESSAGE_TYPE_GAS_FIELDS);
    stamp(m, 3);
    all.emplace_back("error", std::move(m));
  }
  {
    Message m = makeShutdown("campaign finished");
    stamp(m, 7);
    all.emplace_back("shutdown", std::move(m));
  }
  {
    Message m = makeAck("shutting down");
    stamp(m, 7);
    all.emplace_back("ack", std::move(m));
  }
}

} // namespace

int main(int argc, char** argv) {
  if (argc != 2 && argc != 3) {
    std::fprintf(stderr,
                 "usage: coredem-golden-gen OUTPUT_DIR [MINOR]   (e.g. protocol/golden/v1.1 1)\n");
    return 2;
  }
  const int minor = argc == 3 ? std::atoi(argv[2]) : 0;
  if (minor < 0 || minor > 6) {
    std::fprintf(stderr, "coredem-golden-gen: MINOR must be 0 to 6\n");
    return 2;
  }
  std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  Golden all;
  addSessionMessages(all, minor);
  addExchangeMessages(all, minor);
  addControlMessages(all);
  // Every row of the message table (message_types.h) has its golden message.
  for (const auto& row : kMessageTypes) {
    const bool found = std::any_of(all.begin(), all.end(),
                                   [&](const auto& e) { return e.second.type() == row.type; });
    if (!found) {
      std::fprintf(stderr, "coredem-golden-gen: no golden message for '%s': add one above\n",
                   std::string(row.field).c_str());
      return 1;
    }
  }
  for (const auto& [name, message] : all) {
    auto path = dir / (name + ".cdmf");
    writeMultipartFile(path, message.encode());
    std::printf("wrote %s (%zu arrays)\n", path.string().c_str(), message.arrayCount());
  }
  return 0;
}
