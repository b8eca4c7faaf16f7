// Golden v1.0 messages (protocol/golden/v1.0, written once by coredem-golden-gen): decoded
// with the current code forever; every value is checked against the literals below.
// A failure here means a wire-incompatible change: fix the code, do not regenerate the files.
#include <filesystem>

#include <gtest/gtest.h>

#include <coredem/protocol/fields.h>
#include <coredem/protocol/message.h>
#include <coredem/protocol/multipart_file.h>
#include <coredem/protocol/validate.h>

using namespace coredem::protocol;
namespace v1 = coredem::v1;

namespace {

const std::filesystem::path kDir = std::filesystem::path(COREDEM_GOLDEN_DIR) / "v1.0";

Message load(const std::string& name, v1::MessageType type) {
  Frames frames = readMultipartFile(kDir / (name + ".cdmf"));
  Status s;
  Message m = Message::decode(frames, &s);
  EXPECT_TRUE(s.ok()) << name << ": " << s.toString();
  EXPECT_EQ(m.type(), type) << name;
  Status v = validate(m, {});
  if (type != v1::MESSAGE_TYPE_GAS_FIELDS && type != v1::MESSAGE_TYPE_SOURCES) {
    EXPECT_TRUE(v.ok()) << name << ": " << v.toString();
  }
  return m;
}

void expectStamp(const Message& m, std::uint64_t seq) {
  EXPECT_EQ(m.envelope().session_id(), "golden-session");
  EXPECT_EQ(m.envelope().sequence(), seq);
  EXPECT_EQ(m.envelope().step(), 3);
  EXPECT_EQ(m.envelope().time(), 0.25);
  EXPECT_EQ(m.envelope().sender(), "coredem-golden-gen 1.0");
}

/// Golden array values: field f (fields.h order), flat index i -> 0.25 (f+1) + 0.125 i.
void expectFieldArrays(const Message& m, std::span<const fields::FieldSpec> specs) {
  ASSERT_EQ(m.arrayCount(), specs.size());
  std::size_t f = 0;
  for (const auto& spec : specs) {
    ArrayView v = m.array(f);
    EXPECT_EQ(v.name(), spec.name);
    EXPECT_EQ(v.dtype(), v1::DTYPE_FLOAT64);
    EXPECT_EQ(v.shape(), fields::shapeOf(spec.extent, 2, 2));
    auto values = v.as<double>();
    ASSERT_EQ(values.size(), 2 * fields::componentsOf(spec.extent, 2));
    for (std::size_t i = 0; i < values.size(); ++i) {
      EXPECT_EQ(values[i], 0.25 * double(f + 1) + 0.125 * double(i))
          << spec.name << "[" << i << "]";
    }
    ++f;
  }
}

} // namespace

TEST(GoldenV1_0, EveryMessageTypeHasAGoldenFile) {
  // Every row of the message table; types of later minors get golden files in their own
  // version folder.
  for (const auto& row : kMessageTypes) {
    if (row.type <= v1::MESSAGE_TYPE_ACK) {
      EXPECT_TRUE(std::filesystem::exists(kDir / (std::string(row.field) + ".cdmf"))) << row.field;
    }
  }
}

TEST(GoldenV1_0, Hello) {
  Message m = load("hello", v1::MESSAGE_TYPE_HELLO);
  const auto& h = m.envelope().hello();
  EXPECT_EQ(m.envelope().sequence(), 1u);
  EXPECT_EQ(h.protocol_major(), 1u);
  EXPECT_EQ(h.protocol_minor(), 0u);
  EXPECT_EQ(h.software_version(), "coredem-gas 0.1.0");
  EXPECT_EQ(h.role(), v1::ROLE_CFD);
  ASSERT_EQ(h.capabilities_size(), 2);
  EXPECT_EQ(h.capabilities(0), "gas_fields");
  EXPECT_EQ(h.capabilities(1), "checkpoint");
  ASSERT_EQ(h.fields_size(), 1);
  EXPECT_EQ(h.fields(0).name(), "u_g");
  EXPECT_EQ(h.fields(0).dtype(), v1::DTYPE_FLOAT64);
  EXPECT_EQ(h.fields(0).extent(), v1::EXTENT_VECTOR3);
  EXPECT_EQ(h.fields(0).direction(), v1::FIELD_DIRECTION_SENDS);
  EXPECT_EQ(h.fields(0).unit(), "m/s");
}

TEST(GoldenV1_0, WelcomeAndReject) {
  Message w = load("welcome", v1::MESSAGE_TYPE_WELCOME);
  expectStamp(w, 1);
  EXPECT_EQ(w.envelope().welcome().protocol_major(), 1u);
  EXPECT_EQ(w.envelope().welcome().protocol_minor(), 0u);
  EXPECT_EQ(w.envelope().welcome().software_version(), "coredem-dem 0.1.0");
  EXPECT_EQ(w.envelope().welcome().role(), v1::ROLE_DEM);
  EXPECT_EQ(w.envelope().welcome().session_id(), "golden-session");
  ASSERT_EQ(w.envelope().welcome().capabilities_size(), 1);
  EXPECT_EQ(w.envelope().welcome().capabilities(0), "cpu");

  Message r = load("reject", v1::MESSAGE_TYPE_REJECT);
  expectStamp(r, 1);
  EXPECT_EQ(r.envelope().reject().code(), v1::ERROR_CODE_VERSION);
  EXPECT_EQ(r.envelope().reject().reason(), "protocol 1.0 vs 2.3");
  EXPECT_EQ(r.envelope().reject().server_protocol_major(), 1u);
  EXPECT_EQ(r.envelope().reject().server_protocol_minor(), 0u);
}

TEST(GoldenV1_0, Configure) {
  Message m = load("configure", v1::MESSAGE_TYPE_CONFIGURE);
  expectStamp(m, 2);
  const auto& c = m.envelope().configure();
  EXPECT_TRUE(validateConfigure(c).ok()) << validateConfigure(c).toString();
  EXPECT_EQ(c.case_name(), "golden");
  ASSERT_TRUE(c.coupling_mesh().has_cartesian());
  const auto& g = c.coupling_mesh().cartesian();
  EXPECT_EQ(g.origin().x(), -0.5);
  EXPECT_EQ(g.origin().y(), 0.0);
  EXPECT_EQ(g.origin().z(), 0.25);
  EXPECT_EQ(g.spacing().x(), 0.5);
  EXPECT_EQ(g.spacing().y(), 1.0);
  EXPECT_EQ(g.spacing().z(), 2.0);
  EXPECT_EQ(g.counts().x(), 2u);
  EXPECT_EQ(g.counts().y(), 1u);
  EXPECT_EQ(g.counts().z(), 1u);
  ASSERT_EQ(c.species_size(), 2);
  EXPECT_EQ(c.species(0).name(), "O2");
  EXPECT_EQ(c.species(0).molar_mass(), 0.032);
  EXPECT_EQ(c.species(1).name(), "N2");
  EXPECT_EQ(c.species(1).molar_mass(), 0.028);
  ASSERT_TRUE(c.gas().has_constant());
  EXPECT_EQ(c.gas().constant().density(), 1.2);
  EXPECT_EQ(c.gas().constant().viscosity(), 1.8e-5);
  EXPECT_EQ(c.gas().constant().conductivity(), 0.026);
  EXPECT_EQ(c.gas().constant().cp(), 1005.0);
  EXPECT_EQ(c.gas().constant().temperature(), 300.0);
  EXPECT_EQ(c.gas().constant().pressure(), 101325.0);
  ASSERT_EQ(c.particle_sets_size(), 1);
  const auto& p = c.particle_sets(0);
  EXPECT_EQ(p.material_id(), 1u);
  EXPECT_EQ(p.count(), 100u);
  EXPECT_EQ(p.diameter(), 1e-3);
  EXPECT_EQ(p.density(), 0.0);
  EXPECT_EQ(p.temperature(), 1073.15);
  ASSERT_EQ(p.composition_size(), 2);
  EXPECT_EQ(p.composition(0).name(), "Fe2O3");
  EXPECT_EQ(p.composition(0).value(), 0.6);
  EXPECT_EQ(p.composition(1).name(), "Al2O3");
  EXPECT_EQ(p.composition(1).value(), 0.4);
  EXPECT_EQ(p.packing(), v1::PACKING_RANDOM);
  EXPECT_EQ(p.region_min().x(), -0.5);
  EXPECT_EQ(p.region_min().z(), 0.25);
  EXPECT_EQ(p.region_max().x(), 0.5);
  EXPECT_EQ(p.region_max().y(), 1.0);
  EXPECT_EQ(p.region_max().z(), 2.25);
  EXPECT_EQ(p.seed(), 42u);
  EXPECT_EQ(p.initial_velocity().z(), -0.5);
  EXPECT_EQ(p.name(), "carrier");
  ASSERT_EQ(c.materials_size(), 1);
  const auto& mat = c.materials(0);
  EXPECT_EQ(mat.id(), 1u);
  EXPECT_EQ(mat.name(), "ilmenite");
  EXPECT_EQ(mat.density(), 4200.0);
  EXPECT_EQ(mat.k_n(), 1000.0);
  EXPECT_EQ(mat.e_n(), 0.9);
  EXPECT_EQ(mat.friction(), 0.3);
  EXPECT_TRUE(mat.has_kt_factor());
  EXPECT_EQ(ktFactor(mat), 0.25);
  EXPECT_FALSE(mat.has_etat_factor());
  EXPECT_EQ(etatFactor(mat), 0.5);
  EXPECT_EQ(mat.cp(), 850.0);
  EXPECT_EQ(mat.conductivity(), 2.5);
  EXPECT_EQ(mat.emissivity(), 0.8);
  ASSERT_TRUE(c.walls().has_box());
  EXPECT_EQ(c.walls().box().min().x(), -0.5);
  EXPECT_EQ(c.walls().box().max().z(), 2.25);
  ASSERT_EQ(c.walls().planes_size(), 1);
  EXPECT_EQ(c.walls().planes(0).point().z(), 0.25);
  EXPECT_EQ(c.walls().planes(0).normal().z(), 1.0);
  EXPECT_EQ(c.walls().material_id(), 1u);
  EXPECT_EQ(c.gravity().z(), -9.81);
  EXPECT_EQ(c.initial_state_file(), "");
  EXPECT_EQ(c.sub_cycling().dt_cfd(), 1e-4);
  EXPECT_EQ(c.sub_cycling().n_sub(), 50u);
  EXPECT_EQ(c.sub_cycling().dt_dem(), 2e-6);
  EXPECT_EQ(c.start_step(), 3);
  EXPECT_EQ(c.start_time(), 0.25);
  ASSERT_EQ(c.options_size(), 1);
  EXPECT_EQ(c.options(0).key(), "drag");
  EXPECT_EQ(c.options(0).value(), "gidaspow");
  EXPECT_EQ(c.output_directory(), "out");

  Message d = load("configured", v1::MESSAGE_TYPE_CONFIGURED);
  expectStamp(d, 2);
  EXPECT_EQ(d.envelope().configured().cell_count(), 2u);
  EXPECT_EQ(d.envelope().configured().particle_count(), 100u);
  EXPECT_EQ(d.envelope().configured().species_count(), 2u);
  EXPECT_EQ(d.envelope().configured().n_sub(), 50u);
  EXPECT_EQ(d.envelope().configured().dt_dem(), 2e-6);
}

TEST(GoldenV1_0, GasFieldsAndSources) {
  Expectation e;
  e.cells = 2;
  e.species = 2;
  e.step = 3;

  Message g = load("gas_fields", v1::MESSAGE_TYPE_GAS_FIELDS);
  expectStamp(g, 3);
  EXPECT_TRUE(validate(g, e).ok()) << validate(g, e).toString();
  EXPECT_EQ(g.envelope().gas_fields().dt(), 1e-4);
  EXPECT_EQ(g.envelope().gas_fields().cell_count(), 2u);
  EXPECT_EQ(g.envelope().gas_fields().species_count(), 2u);
  expectFieldArrays(g, fields::gasFields());

  Message s = load("sources", v1::MESSAGE_TYPE_SOURCES);
  expectStamp(s, 3);
  EXPECT_TRUE(validate(s, e).ok()) << validate(s, e).toString();
  const auto& b = s.envelope().sources();
  EXPECT_EQ(b.dt(), 1e-4);
  EXPECT_EQ(b.cell_count(), 2u);
  EXPECT_EQ(b.species_count(), 2u);
  EXPECT_EQ(b.substeps(), 50u);
  EXPECT_EQ(findNamedValue(b.ledger().mass(), "particles"), 0.0132);
  EXPECT_EQ(findNamedValue(b.ledger().energy(), "particles"), 5.5e3);
  EXPECT_EQ(findNamedValue(b.ledger().species(), "O2"), -1.5e-6);
  expectFieldArrays(s, fields::sourceFields());
}

TEST(GoldenV1_0, StepGrantAndStepDone) {
  Message g = load("step_grant", v1::MESSAGE_TYPE_STEP_GRANT);
  expectStamp(g, 4);
  EXPECT_EQ(g.envelope().step_grant().dt_cfd(), 1e-4);
  EXPECT_EQ(g.envelope().step_grant().n_sub(), 50u);
  EXPECT_EQ(g.envelope().step_grant().dt_dem(), 2e-6);

  Message d = load("step_done", v1::MESSAGE_TYPE_STEP_DONE);
  expectStamp(d, 4);
  const auto& b = d.envelope().step_done();
  EXPECT_EQ(b.cfl(), 0.35);
  EXPECT_EQ(b.max_dt(), 2e-4);
  EXPECT_EQ(b.wall_seconds(), 0.125);
  EXPECT_EQ(findNamedValue(b.ledger().mass(), "gas_in"), 1.5);
  EXPECT_EQ(findNamedValue(b.ledger().energy(), "gas_in"), 300.0);
  EXPECT_EQ(findNamedValue(b.ledger().species(), "CO2"), 2.5e-3);
  EXPECT_EQ(findNamedValue(b.diagnostics(), "mean_T_p"), 1050.5);
  EXPECT_EQ(findNamedValue(b.diagnostics(), "absent"), std::nullopt);
}

TEST(GoldenV1_0, Checkpoints) {
  Message r = load("checkpoint_request", v1::MESSAGE_TYPE_CHECKPOINT_REQUEST);
  expectStamp(r, 5);
  EXPECT_EQ(r.envelope().checkpoint_request().directory(), "checkpoints/3");
  EXPECT_EQ(r.envelope().checkpoint_request().tag(), "periodic");

  Message d = load("checkpoint_done", v1::MESSAGE_TYPE_CHECKPOINT_DONE);
  expectStamp(d, 5);
  EXPECT_EQ(d.envelope().checkpoint_done().directory(), "checkpoints/3");
  ASSERT_EQ(d.envelope().checkpoint_done().files_size(), 2);
  EXPECT_EQ(d.envelope().checkpoint_done().files(0), "dem.h5");
  EXPECT_EQ(d.envelope().checkpoint_done().files(1), "dem.json");
}

TEST(GoldenV1_0, HeartbeatErrorShutdownAck) {
  Message h = load("heartbeat", v1::MESSAGE_TYPE_HEARTBEAT);
  expectStamp(h, 6);
  EXPECT_EQ(h.envelope().heartbeat().unix_time(), 1.75e9);
  EXPECT_EQ(h.envelope().heartbeat().state(), "stepping");

  Message e = load("error", v1::MESSAGE_TYPE_ERROR);
  expectStamp(e, 3);
  EXPECT_EQ(e.envelope().error().code(), v1::ERROR_CODE_NON_FINITE);
  EXPECT_EQ(e.envelope().error().message(), "array 'T_g' contains NaN at flat index 1");
  EXPECT_EQ(e.envelope().error().offending_sequence(), 3u);
  EXPECT_EQ(e.envelope().error().offending_type(), v1::MESSAGE_TYPE_GAS_FIELDS);

  Message s = load("shutdown", v1::MESSAGE_TYPE_SHUTDOWN);
  expectStamp(s, 7);
  EXPECT_EQ(s.envelope().shutdown().reason(), "campaign finished");

  Message a = load("ack", v1::MESSAGE_TYPE_ACK);
  expectStamp(a, 7);
  EXPECT_EQ(a.envelope().ack().note(), "shutting down");
}
