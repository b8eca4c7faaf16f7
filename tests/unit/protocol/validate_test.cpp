// Validation of received messages (docs/protocol.md): each violation yields its own code and a
// message naming the field.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include <coredem/protocol/validate.h>

#include "test_messages.h"

using namespace coredem::protocol;
namespace v1 = coredem::v1;

namespace {

constexpr std::uint64_t kCells = 12;
constexpr std::uint32_t kSpecies = 3;

Expectation gasExpectation() {
  Expectation e;
  e.types = {v1::MESSAGE_TYPE_GAS_FIELDS};
  e.cells = kCells;
  e.species = kSpecies;
  return e;
}

/// Re-decodes a message after `edit` changed its envelope (array frames unchanged).
template <class Edit>
Message withEnvelope(const Message& m, Edit edit) {
  Frames frames = m.encode();
  v1::Envelope env = m.envelope();
  edit(env);
  frames[0] = env.SerializeAsString();
  Status s;
  Message r = Message::decode(frames, &s);
  EXPECT_TRUE(s.ok()) << s.toString();
  return r;
}

/// Replaces array `name` by `values` with the given dtype/shape.
template <class T>
Message withArray(const Message& m, const std::string& name, const std::vector<T>& values,
                  std::vector<std::uint64_t> shape) {
  Message r(m.envelope());
  for (std::size_t i = 0; i < m.arrayCount(); ++i) {
    ArrayView v = m.array(i);
    if (v.name() == name) {
      r.addArray<T>(name, values, shape);
    } else {
      r.addArrayBytes(v.name(), v.dtype(), v.shape(), v.bytes);
    }
  }
  return r;
}

} // namespace

TEST(Validate, AcceptsAValidGasFieldsMessage) {
  Message m = test::gasFieldsMessage(kCells, kSpecies, 4, 7);
  Expectation e = gasExpectation();
  e.step = 4;
  e.sequence = 7;
  Status s = validate(m, e);
  EXPECT_TRUE(s.ok()) << s.toString();
}

TEST(Validate, RejectsNaNAndInfNamingFieldAndFirstIndex) {
  Message m = test::gasFieldsMessage(kCells, kSpecies);
  std::vector<double> t(kCells, 300.0);
  t[5] = std::numeric_limits<double>::quiet_NaN();
  t[9] = std::numeric_limits<double>::infinity();
  Status s = validate(withArray<double>(m, "T_g", t, {kCells}), gasExpectation());
  EXPECT_EQ(s.code, v1::ERROR_CODE_NON_FINITE);
  EXPECT_NE(s.message.find("'T_g'"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("NaN at flat index 5"), std::string::npos) << s.message;

  std::vector<double> u(kCells * 3, 0.0);
  u[3 * 2 + 1] = -std::numeric_limits<double>::infinity();
  s = validate(withArray<double>(m, "u_g", u, {kCells, 3}), gasExpectation());
  EXPECT_EQ(s.code, v1::ERROR_CODE_NON_FINITE);
  EXPECT_NE(s.message.find("-Inf at flat index 7 (row 2, column 1)"), std::string::npos)
      << s.message;

  Expectation lenient = gasExpectation();
  lenient.requireFinite = false;
  EXPECT_TRUE(validate(withArray<double>(m, "T_g", t, {kCells}), lenient).ok());
}

TEST(Validate, RejectsWrongDtypeShapeMissingAndDuplicateArrays) {
  Message m = test::gasFieldsMessage(kCells, kSpecies);

  std::vector<float> f(kCells, 1.0f);
  Status s = validate(withArray<float>(m, "rho_g", f, {kCells}), gasExpectation());
  EXPECT_EQ(s.code, v1::ERROR_CODE_DTYPE);
  EXPECT_NE(s.message.find("'rho_g'"), std::string::npos);

  std::vector<double> d(kCells * 3, 1.0);
  s = validate(withArray<double>(m, "grad_p", d, {kCells * 3}), gasExpectation());
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);
  EXPECT_NE(s.message.find("[36]"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("[12,3]"), std::string::npos) << s.message;

  std::vector<double> y(kCells * 2, 0.5); // 2 species columns, 3 configured
  s = validate(withArray<double>(m, "Y_g", y, {kCells, 2}), gasExpectation());
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);

  Message missing(m.envelope());
  for (std::size_t i = 0; i + 1 < m.arrayCount(); ++i) {
    ArrayView v = m.array(i);
    missing.addArrayBytes(v.name(), v.dtype(), v.shape(), v.bytes);
  }
  s = validate(missing, gasExpectation());
  EXPECT_EQ(s.code, v1::ERROR_CODE_MISSING_FIELD);
  EXPECT_NE(s.message.find("'Y_g'"), std::string::npos);

  // Duplicate: two descriptors with the same name (only possible on the wire).
  Frames frames = m.encode();
  v1::Envelope env = m.envelope();
  env.mutable_arrays(3)->set_name("T_g");
  frames[0] = env.SerializeAsString();
  Status ds;
  Message dup = Message::decode(frames, &ds);
  ASSERT_TRUE(ds.ok());
  EXPECT_EQ(validate(dup, gasExpectation()).code, v1::ERROR_CODE_DUPLICATE_FIELD);
}

TEST(Validate, ExtraArraysAreAllowedButChecked) {
  Message m = test::gasFieldsMessage(kCells, kSpecies);
  std::vector<double> extra{1.0, std::nan("")};
  m.addArray<double>("future_field", extra, {2});
  Status s = validate(m, gasExpectation());
  EXPECT_EQ(s.code, v1::ERROR_CODE_NON_FINITE);
  EXPECT_NE(s.message.find("future_field"), std::string::npos);
}

TEST(Validate, CountsDeclaredInTheBodyMustMatch) {
  Message m = test::gasFieldsMessage(kCells, kSpecies);
  Message other =
      withEnvelope(m, [](v1::Envelope& e) { e.mutable_gas_fields()->set_cell_count(11); });
  EXPECT_EQ(validate(other, gasExpectation()).code, v1::ERROR_CODE_SHAPE);
}

TEST(Validate, TypeSessionSequenceAndStep) {
  Message m = test::gasFieldsMessage(kCells, kSpecies, 3, 10);
  m.setSessionId("abc");

  Message unknown =
      withEnvelope(m, [](v1::Envelope& e) { e.set_type(static_cast<v1::MessageType>(99)); });
  Status s = validate(unknown, {});
  EXPECT_EQ(s.code, v1::ERROR_CODE_UNKNOWN_TYPE);
  EXPECT_NE(s.message.find("99"), std::string::npos);

  Message unspecified =
      withEnvelope(m, [](v1::Envelope& e) { e.set_type(v1::MESSAGE_TYPE_UNSPECIFIED); });
  EXPECT_EQ(validate(unspecified, {}).code, v1::ERROR_CODE_UNKNOWN_TYPE);

  Message mismatch = withEnvelope(m, [](v1::Envelope& e) { e.set_type(v1::MESSAGE_TYPE_SOURCES); });
  EXPECT_EQ(validate(mismatch, {}).code, v1::ERROR_CODE_BODY_MISMATCH);

  Expectation e = gasExpectation();
  e.types = {v1::MESSAGE_TYPE_CONFIGURE};
  EXPECT_EQ(validate(m, e).code, v1::ERROR_CODE_UNEXPECTED_MESSAGE);

  e = gasExpectation();
  e.sessionId = "xyz";
  EXPECT_EQ(validate(m, e).code, v1::ERROR_CODE_UNKNOWN_SESSION);

  e = gasExpectation();
  e.sequence = 11;
  EXPECT_EQ(validate(m, e).code, v1::ERROR_CODE_OUT_OF_ORDER);
  e.sequence.reset();
  e.sequenceAfter = 10;
  EXPECT_EQ(validate(m, e).code, v1::ERROR_CODE_OUT_OF_ORDER);
  e.sequenceAfter = 9;
  EXPECT_TRUE(validate(m, e).ok());

  e = gasExpectation();
  e.step = 2;
  s = validate(m, e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_OUT_OF_ORDER);
  EXPECT_NE(s.message.find("step 3"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("step 2 expected"), std::string::npos) << s.message;

  e = gasExpectation();
  e.cells.reset();
  EXPECT_EQ(validate(m, e).code, v1::ERROR_CODE_NOT_CONFIGURED);
}

namespace {
v1::Configure validConfigure() {
  v1::Configure c;
  auto* g = c.mutable_coupling_mesh()->mutable_cartesian();
  g->mutable_spacing()->set_x(0.01);
  g->mutable_spacing()->set_y(0.01);
  g->mutable_spacing()->set_z(0.01);
  g->mutable_counts()->set_x(4);
  g->mutable_counts()->set_y(3);
  g->mutable_counts()->set_z(1);
  auto* s = c.add_species();
  s->set_name("CO2");
  s->set_molar_mass(0.044);
  c.mutable_sub_cycling()->set_dt_cfd(1e-4);
  c.mutable_sub_cycling()->set_n_sub(3);
  c.mutable_sub_cycling()->set_dt_dem(1e-4 / 3);
  auto* m = c.add_materials();
  m->set_id(2);
  m->set_density(2500);
  m->set_k_n(1e3);
  m->set_e_n(0.9);
  m->set_friction(0.3);
  auto* p = c.add_particle_sets();
  p->set_material_id(2);
  p->set_count(10);
  p->set_diameter(1e-3);
  p->set_temperature(300);
  p->set_packing(v1::PACKING_LATTICE);
  p->mutable_region_max()->set_x(0.04);
  p->mutable_region_max()->set_y(0.03);
  p->mutable_region_max()->set_z(0.01);
  auto* y = p->add_composition();
  y->set_name("C");
  y->set_value(0.7);
  y = p->add_composition();
  y->set_name("ash");
  y->set_value(0.3);
  return c;
}
} // namespace

TEST(ValidateConfigure, AcceptsAConsistentCase) {
  Status s = validateConfigure(validConfigure());
  EXPECT_TRUE(s.ok()) << s.toString();
  EXPECT_EQ(cellCount(validConfigure().coupling_mesh()), 12u);
}

TEST(ValidateConfigure, RejectsInconsistentCases) {
  auto expectBad = [](v1::Configure c, const std::string& needle) {
    Status s = validateConfigure(c);
    EXPECT_EQ(s.code, v1::ERROR_CODE_INVALID_CONFIGURATION) << needle;
    EXPECT_NE(s.message.find(needle), std::string::npos) << s.message;
  };
  v1::Configure c = validConfigure();
  c.mutable_sub_cycling()->set_dt_dem(1e-4 / 3 * (1 + 1e-9));
  expectBad(c, "dt_dem");

  c = validConfigure();
  c.mutable_coupling_mesh()->clear_cartesian();
  expectBad(c, "CartesianGrid");

  c = validConfigure();
  c.mutable_coupling_mesh()->mutable_cartesian()->mutable_counts()->set_y(0);
  expectBad(c, "counts");

  c = validConfigure();
  c.mutable_species(0)->set_molar_mass(0);
  expectBad(c, "molar_mass");

  c = validConfigure();
  *c.add_species() = c.species(0);
  expectBad(c, "unique");

  c = validConfigure();
  c.mutable_particle_sets(0)->set_material_id(7);
  expectBad(c, "material 7");

  c = validConfigure();
  c.mutable_particle_sets(0)->mutable_composition(0)->set_value(0.69);
  expectBad(c, "sum to");

  c = validConfigure();
  c.mutable_materials(0)->set_e_n(1.5);
  expectBad(c, "e_n");

  // An initial state file replaces the particle sets: their contents are not checked.
  c = validConfigure();
  c.mutable_particle_sets(0)->set_material_id(7);
  c.set_initial_state_file("state.h5");
  EXPECT_TRUE(validateConfigure(c).ok());
}

// v1.6: the Hertz–Mindlin properties, material pairs and wall materials; k_n 0 (not given) is
// the DEM's to refuse for the law that needs it.
TEST(ValidateConfigure, ChecksTheContactMaterialsOfV16) {
  auto expectBad = [](const v1::Configure& c, const std::string& needle) {
    const Status s = validateConfigure(c);
    EXPECT_EQ(s.code, v1::ERROR_CODE_INVALID_CONFIGURATION) << needle;
    EXPECT_NE(s.message.find(needle), std::string::npos) << s.message;
  };
  v1::Configure c = validConfigure();
  const std::uint32_t id = c.materials(0).id();
  c.mutable_materials(0)->set_k_n(0.0);
  c.mutable_materials(0)->set_youngs_modulus(1e8);
  c.mutable_materials(0)->set_poisson_ratio(0.3);
  auto* pair = c.add_material_pairs();
  pair->set_material_a(id);
  pair->set_material_b(id);
  pair->set_friction(0.0);
  auto* plane = c.mutable_walls()->add_planes();
  plane->mutable_normal()->set_z(1.0);
  plane->set_material_id(id);
  EXPECT_TRUE(validateConfigure(c).ok()) << validateConfigure(c).toString();

  v1::Configure b = c;
  b.mutable_materials(0)->set_poisson_ratio(0.5);
  expectBad(b, "poisson_ratio");
  b = c;
  b.mutable_materials(0)->set_youngs_modulus(0.0);
  expectBad(b, "youngs_modulus");
  b = c;
  b.mutable_material_pairs(0)->set_material_b(id + 7);
  expectBad(b, "material_pairs[0]");
  b = c;
  b.mutable_material_pairs(0)->set_e_n(0.0);
  expectBad(b, "material_pairs[0] needs");
  b = c;
  b.mutable_walls()->mutable_planes(0)->set_material_id(id + 7);
  expectBad(b, "walls.planes[0] has material_id");
  b = c;
  b.mutable_walls()->mutable_box()->set_material_id(id + 7);
  expectBad(b, "walls.box");
}

TEST(ValidateConfigure, ChecksTheChemistryFieldsOfV11) {
  auto withReaction = [] {
    v1::Configure c = validConfigure();
    auto* s = c.add_solid_species();
    s->set_name("B");
    s->set_molar_mass(0.015);
    auto* r = c.add_reactions();
    r->set_name("rc");
    auto* t = r->add_terms();
    t->set_species("B");
    t->set_nu(-1.0);
    r->mutable_rate()->set_law(v1::RATE_LAW_CONSTANT);
    r->mutable_rate()->set_a(1e-4);
    c.mutable_chemistry()->set_removal_fraction(0.1);
    return c;
  };
  EXPECT_TRUE(validateConfigure(withReaction()).ok()) << validateConfigure(withReaction()).message;
  auto expectBad = [](const v1::Configure& c, const std::string& needle) {
    Status s = validateConfigure(c);
    EXPECT_EQ(s.code, v1::ERROR_CODE_INVALID_CONFIGURATION) << needle;
    EXPECT_NE(s.message.find(needle), std::string::npos) << s.message;
  };
  v1::Configure c = withReaction();
  c.mutable_solid_species(0)->set_molar_mass(0.0);
  expectBad(c, "solid_species 'B'");
  c = withReaction();
  c.mutable_solid_species(0)->set_name(c.species(0).name());
  expectBad(c, "repeated");
  c = withReaction();
  c.mutable_reactions(0)->mutable_terms(0)->set_nu(0.0);
  expectBad(c, "nonzero nu");
  c = withReaction();
  c.mutable_reactions(0)->mutable_rate()->set_law(v1::RATE_LAW_UNSPECIFIED);
  expectBad(c, "rate.law");
  c = withReaction();
  c.mutable_chemistry()->set_removal_fraction(1.5);
  expectBad(c, "removal_fraction");
}

TEST(ValidateConfigure, RefusesGridsWhoseCellCountOverflowsOrExceedsTheLimit) {
  auto c = validConfigure();
  auto* counts = c.mutable_coupling_mesh()->mutable_cartesian()->mutable_counts();
  counts->set_x(4294967295u); // (2^32-1)^2 * 4 wraps around 2^64 (a wrapped product was 0 cells)
  counts->set_y(4294967295u);
  counts->set_z(4);
  EXPECT_EQ(cellCount(c.coupling_mesh()), std::numeric_limits<std::uint64_t>::max());
  Status s = validateConfigure(c);
  EXPECT_EQ(s.code, v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_NE(s.message.find("overflow"), std::string::npos) << s.message;
  counts->set_x(65536); // 2^32 cells: no overflow, but past kMaxCells
  counts->set_y(65536);
  counts->set_z(1);
  EXPECT_EQ(cellCount(c.coupling_mesh()), std::uint64_t{1} << 32);
  s = validateConfigure(c);
  EXPECT_EQ(s.code, v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_NE(s.message.find("4294967296"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find(std::to_string(kMaxCells)), std::string::npos) << s.message;
}

TEST(Printable, EscapesControlCharactersAndCapsTheLength) {
  EXPECT_EQ(printable("plain name 1.0"), "plain name 1.0");
  EXPECT_EQ(printable("a\nb\rc\td\\e\"f"), "a\\nb\\rc\\td\\\\e\\\"f");
  EXPECT_EQ(printable(std::string("x\0y\x1b[31m\xff", 9)), "x\\x00y\\x1b[31m\\xff");
  const std::string longText(100000, 'z');
  const std::string cut = printable(longText, 10);
  EXPECT_EQ(cut, "zzzzzzzzzz...(100000 bytes)");
  EXPECT_EQ(printable(longText).size(), 160u + std::string("...(100000 bytes)").size());
}

TEST(Validate, PeerStringsInRefusalsAreEscaped) {
  // An array name with a newline (a forged log line) comes back escaped.
  auto m = makeHeartbeat("probe");
  std::vector<double> v(4, std::nan(""));
  m.addArray("evil\n[info] forged", v, {4});
  Expectation e;
  Status s = validate(m, e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_NON_FINITE);
  EXPECT_EQ(s.message.find('\n'), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("evil\\n[info] forged"), std::string::npos) << s.message;
}

namespace {
/// A GasFields message of air at 300 K in `cells` cells with one species (Y = 1), with `edit`
/// applied to the named array first.
template <class Edit>
Message physicalGas(std::uint64_t cells, std::string_view edited, Edit edit) {
  namespace f = fields;
  Message m = makeGasFields(1, 0.0, 1e-3, cells, 1);
  const std::pair<std::string_view, double> values[] = {
      {f::kGasVelocity, 0.5},      {f::kPressureGradient, -1e4}, {f::kGasTemperature, 300.0},
      {f::kGasDensity, 1.2},       {f::kGasViscosity, 1.8e-5},   {f::kGasConductivity, 0.026},
      {f::kGasHeatCapacity, 1005}, {f::kGasMassFractions, 1.0}};
  for (const auto& [name, value] : values) {
    const auto shape = f::shapeOf(name, cells, 1);
    std::vector<double> v(cells * (shape.size() > 1 ? shape[1] : 1), value);
    if (name == edited) {
      edit(v);
    }
    m.addArray<double>(name, v, shape);
  }
  return m;
}
} // namespace

TEST(ValidateGasRanges, AcceptsPhysicalFieldsAndNamesTheFirstValueOutsideItsRange) {
  const auto none = [](std::vector<double>&) {};
  EXPECT_TRUE(validateGasRanges(physicalGas(4, "", none)).ok());
  struct Case {
    std::string_view array;
    std::size_t index;
    double value;
    const char* needle;
  };
  const Case cases[] = {
      {fields::kGasTemperature, 2, 20.0, "cell 2: T_g = 20 K"},
      {fields::kGasTemperature, 0, 1e7, "T_g = 1e+07 K"},
      {fields::kGasViscosity, 3, 1e-310, "mu_g"},
      {fields::kGasDensity, 1, 0.0, "rho_g"},
      {fields::kGasConductivity, 1, 1e30, "kappa_g"},
      {fields::kGasHeatCapacity, 1, 1.0, "cp_g"},
      {fields::kGasVelocity, 3 * 2 + 1, 2e4, "cell 2: |u_g|"},
      {fields::kPressureGradient, 0, 1e13, "|grad_p|"},
      {fields::kGasMassFractions, 3, 0.9, "cell 3: sum of Y = 0.9"},
      {fields::kGasMassFractions, 0, 1.5, "Y of species 0 = 1.5"},
  };
  for (const Case& c : cases) {
    const Status s = validateGasRanges(
        physicalGas(4, c.array, [&](std::vector<double>& v) { v[c.index] = c.value; }));
    EXPECT_EQ(s.code, v1::ERROR_CODE_INVALID_CONFIGURATION) << c.needle;
    EXPECT_NE(s.message.find(c.needle), std::string::npos) << s.message;
  }
  // A sum off by less than the tolerance passes (OpenFOAM's species rarely sum to 1 exactly).
  EXPECT_TRUE(
      validateGasRanges(physicalGas(4, fields::kGasMassFractions, [](std::vector<double>& v) {
        v[0] = 0.99;
      })).ok());
}

// The optional fluid_fraction array (a CFD mesh that leaves coupling cells partly outside the
// fluid): accepted with one value per cell in [0, 1]; another shape or a value outside [0, 1] is
// refused naming it.
TEST(ValidateGasRanges, OptionalFluidFractionHasOneValuePerCellInZeroOne) {
  const auto none = [](std::vector<double>&) {};
  Expectation e;
  e.types = {v1::MESSAGE_TYPE_GAS_FIELDS};
  e.cells = 4;
  e.species = 1;
  Message ok = physicalGas(4, "", none);
  ok.addArray<double>(fields::kFluidFraction, std::vector<double>{1.0, 0.5, 0.0, 1.0}, {4});
  EXPECT_TRUE(validate(ok, e).ok()) << validate(ok, e).toString();
  EXPECT_TRUE(validateGasRanges(ok).ok());
  Message wide = physicalGas(4, "", none);
  wide.addArray<double>(fields::kFluidFraction, std::vector<double>{1.0, 1.2, 0.0, 1.0}, {4});
  const Status s = validateGasRanges(wide);
  EXPECT_EQ(s.code, v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_NE(s.message.find("cell 1: fluid_fraction = 1.2"), std::string::npos) << s.message;
  Message shape = physicalGas(4, "", none);
  shape.addArray<double>(fields::kFluidFraction, std::vector<double>{1.0, 1.0, 1.0}, {3});
  const Status t = validate(shape, e);
  EXPECT_EQ(t.code, v1::ERROR_CODE_SHAPE);
  EXPECT_NE(t.message.find("fluid_fraction"), std::string::npos) << t.message;
}

// Partial GasFields (v1.2, one rank of a decomposed CFD): the listed cells in range, ascending,
// without duplicates; the counts consistent; fluid volumes positive; every field M rows.
namespace {
Message partialGas(std::vector<std::int64_t> cells, std::vector<double> volume,
                   std::uint64_t touched) {
  Message m = makeGasFields(1, 0.0, 1e-3, 4, 1);
  m.envelope().mutable_gas_fields()->set_partial(true);
  m.envelope().mutable_gas_fields()->set_touched_count(touched);
  const std::uint64_t rows = cells.size();
  m.addArray<std::int64_t>(fields::kTouchedCells, cells, {rows});
  m.addArray<double>(fields::kFluidVolume, volume, {std::uint64_t(volume.size())});
  for (const auto& spec : fields::gasFields()) {
    std::vector<double> v(rows * fields::componentsOf(spec.extent, 1), 1.0);
    m.addArray<double>(spec.name, v, fields::shapeOf(spec.extent, rows, 1));
  }
  return m;
}
Expectation partialExpectation() {
  Expectation e;
  e.types = {v1::MESSAGE_TYPE_GAS_FIELDS};
  e.cells = 4;
  e.species = 1;
  return e;
}
} // namespace

TEST(ValidatePartial, AcceptsAscendingCellsInRange) {
  const Status s = validate(partialGas({0, 3}, {0.5, 1.0}, 2), partialExpectation());
  EXPECT_TRUE(s.ok()) << s.toString();
  EXPECT_TRUE(validate(partialGas({}, {}, 0), partialExpectation()).ok()); // touches nothing
}

TEST(ValidatePartial, RefusesBadListsNamingTheCell) {
  const Expectation e = partialExpectation();
  Status s = validate(partialGas({1, 1}, {0.5, 0.5}, 2), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_DUPLICATE_FIELD);
  EXPECT_NE(s.message.find("cells[1] = 1 is listed twice"), std::string::npos) << s.message;
  s = validate(partialGas({2, 1}, {0.5, 0.5}, 2), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_DUPLICATE_FIELD);
  EXPECT_NE(s.message.find("out of order"), std::string::npos) << s.message;
  s = validate(partialGas({0, 4}, {0.5, 0.5}, 2), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);
  EXPECT_NE(s.message.find("cells[1] = 4 is not a coupling cell (0..3)"), std::string::npos)
      << s.message;
  s = validate(partialGas({0, -1}, {0.5, 0.5}, 2), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);
  // touched_count disagrees with the arrays, or exceeds the grid.
  s = validate(partialGas({0, 1}, {0.5, 0.5}, 3), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);
  EXPECT_NE(s.message.find("'cells'"), std::string::npos) << s.message;
  s = validate(partialGas({0, 1}, {0.5, 0.5}, 5), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);
  // fluid_volume of another length, zero, or NaN.
  s = validate(partialGas({0, 1}, {0.5}, 2), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);
  EXPECT_NE(s.message.find("fluid_volume"), std::string::npos) << s.message;
  s = validate(partialGas({0, 1}, {0.5, 0.0}, 2), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_NE(s.message.find("fluid_volume[1]"), std::string::npos) << s.message;
  s = validate(partialGas({0, 1}, {0.5, std::nan("")}, 2), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_NON_FINITE);
}

TEST(ValidatePartial, RefusesMissingListsAndWholeGridRowsAndFluidFraction) {
  const Expectation e = partialExpectation();
  // A whole-grid GasFields flagged partial lacks the cell list.
  Message whole = makeGasFields(1, 0.0, 1e-3, 4, 1);
  whole.envelope().mutable_gas_fields()->set_partial(true);
  whole.envelope().mutable_gas_fields()->set_touched_count(4);
  for (const auto& spec : fields::gasFields()) {
    std::vector<double> v(4 * fields::componentsOf(spec.extent, 1), 1.0);
    whole.addArray<double>(spec.name, v, fields::shapeOf(spec.extent, 4, 1));
  }
  Status s = validate(whole, e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_MISSING_FIELD);
  EXPECT_NE(s.message.find("'cells'"), std::string::npos) << s.message;
  // int32 cell indices are refused (int64 only).
  Message narrow = makeGasFields(1, 0.0, 1e-3, 4, 1);
  narrow.envelope().mutable_gas_fields()->set_partial(true);
  narrow.envelope().mutable_gas_fields()->set_touched_count(1);
  narrow.addArray<std::int32_t>(fields::kTouchedCells, std::vector<std::int32_t>{0}, {1});
  s = validate(narrow, e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);
  // fluid_fraction is the server's to form.
  Message ff = partialGas({0}, {0.5}, 1);
  ff.addArray<double>(fields::kFluidFraction, std::vector<double>{0.5}, {1});
  s = validate(ff, e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_NE(s.message.find("fluid_fraction"), std::string::npos) << s.message;
}

// Q_rad (v1.3): optional in Sources; when present float64, one row per cell (or listed cell of a
// partial Sources) and finite.
namespace {
Message sourcesWith(std::uint64_t rows, bool partial, std::vector<double> qRad,
                    std::vector<std::uint64_t> qShape) {
  Message m = makeSources(1, 0.0, 1e-3, 4, 1, 10);
  if (partial) {
    m.envelope().mutable_sources()->set_partial(true);
    m.envelope().mutable_sources()->set_touched_count(rows);
    std::vector<std::int64_t> cells(rows);
    for (std::uint64_t i = 0; i < rows; ++i) {
      cells[i] = static_cast<std::int64_t>(i + 1);
    }
    m.addArray<std::int64_t>(fields::kTouchedCells, cells, {rows});
  }
  for (const auto& spec : fields::sourceFields()) {
    std::vector<double> v(rows * fields::componentsOf(spec.extent, 1), 0.5);
    m.addArray<double>(spec.name, v, fields::shapeOf(spec.extent, rows, 1));
  }
  if (!qShape.empty()) {
    m.addArray<double>(fields::kRadiationHeat, qRad, qShape);
  }
  return m;
}
Expectation sourcesExpectation() {
  Expectation e;
  e.types = {v1::MESSAGE_TYPE_SOURCES};
  e.cells = 4;
  e.species = 1;
  return e;
}
} // namespace

TEST(ValidateSources, RadiationHeatIsOptionalAndOnePerCell) {
  const Expectation e = sourcesExpectation();
  EXPECT_TRUE(validate(sourcesWith(4, false, {}, {}), e).ok()); // a v1.2 Sources: no Q_rad
  Status s = validate(sourcesWith(4, false, {1.0, -2.0, 0.0, 3.5}, {4}), e);
  EXPECT_TRUE(s.ok()) << s.toString();
  s = validate(sourcesWith(2, true, {1.0, -2.0}, {2}), e); // partial: one per listed cell
  EXPECT_TRUE(s.ok()) << s.toString();
  // Wrong count (whole grid and partial), wrong shape.
  s = validate(sourcesWith(4, false, {1.0, 2.0, 3.0}, {3}), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);
  EXPECT_NE(s.message.find("'Q_rad'"), std::string::npos) << s.message;
  s = validate(sourcesWith(2, true, {1.0, 2.0, 3.0, 4.0}, {4}), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);
  EXPECT_NE(s.message.find("listed"), std::string::npos) << s.message;
  s = validate(sourcesWith(4, false, {1.0, 2.0, 3.0, 4.0}, {4, 1}), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);
  // Not finite: named with its index.
  s = validate(sourcesWith(4, false, {1.0, 2.0, std::numeric_limits<double>::infinity(), 4.0}, {4}),
               e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_NON_FINITE);
  EXPECT_NE(s.message.find("Q_rad"), std::string::npos) << s.message;
  // float32 is refused like every coupling array.
  Message f32 = sourcesWith(4, false, {}, {});
  f32.addArray<float>(fields::kRadiationHeat, std::vector<float>{1, 2, 3, 4}, {4});
  EXPECT_EQ(validate(f32, e).code, v1::ERROR_CODE_SHAPE);
}

TEST(ValidateSources, RadiationHeatRoundTripsBitwise) {
  const std::vector<double> q = {1.0 / 3.0, -2.5e-7, 0.0, 6.02214076e23};
  const Message m = sourcesWith(4, false, q, {4});
  Status s;
  const Message back = Message::decode(m.encode(), &s);
  ASSERT_TRUE(s.ok()) << s.toString();
  ASSERT_TRUE(validate(back, sourcesExpectation()).ok());
  const auto v = back.values<double>(fields::kRadiationHeat);
  ASSERT_EQ(v.size(), q.size());
  for (std::size_t i = 0; i < q.size(); ++i) {
    EXPECT_EQ(v[i], q[i]) << i;
  }
  EXPECT_NE(fields::findField(fields::kRadiationHeat), nullptr);
  EXPECT_EQ(fields::findField(fields::kRadiationHeat)->unit, "W/m3");
}

// Q_split (v1.5): optional in GasFields, whole grid or partial; when present float64, one row per
// cell (or listed cell) and finite, of either sign.
TEST(ValidateGasFields, HeatToParticlesIsOptionalOnePerCellFiniteOfEitherSign) {
  const Expectation e = partialExpectation(); // 4 cells, 1 species
  const auto whole = [](std::vector<double> q, std::vector<std::uint64_t> shape) {
    Message m = makeGasFields(1, 0.0, 1e-3, 4, 1);
    for (const auto& spec : fields::gasFields()) {
      std::vector<double> v(4 * fields::componentsOf(spec.extent, 1), 1.0);
      m.addArray<double>(spec.name, v, fields::shapeOf(spec.extent, 4, 1));
    }
    if (!shape.empty()) {
      m.addArray<double>(fields::kHeatToParticles, q, shape);
    }
    return m;
  };
  EXPECT_TRUE(validate(whole({}, {}), e).ok()); // a v1.4 GasFields: no Q_split
  Status s = validate(whole({1.5, -2.0, 0.0, 3e6}, {4}), e);
  EXPECT_TRUE(s.ok()) << s.toString();
  // Partial (a rank's own contribution): one value per listed cell.
  Message p = partialGas({0, 3}, {0.5, 1.0}, 2);
  p.addArray<double>(fields::kHeatToParticles, std::vector<double>{-4.0, 2.5}, {2});
  s = validate(p, e);
  EXPECT_TRUE(s.ok()) << s.toString();
  Message pBad = partialGas({0, 3}, {0.5, 1.0}, 2);
  pBad.addArray<double>(fields::kHeatToParticles, std::vector<double>{-4.0, 2.5, 1.0, 1.0}, {4});
  s = validate(pBad, e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);
  EXPECT_NE(s.message.find("'Q_split'"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("listed"), std::string::npos) << s.message;
  // Wrong count or shape on the whole grid.
  s = validate(whole({1.0, 2.0, 3.0}, {3}), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);
  EXPECT_NE(s.message.find("'Q_split'"), std::string::npos) << s.message;
  s = validate(whole({1.0, 2.0, 3.0, 4.0}, {4, 1}), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);
  // NaN and Inf are refused, naming the array and the index (whole grid and partial).
  s = validate(whole({1.0, std::nan(""), 3.0, 4.0}, {4}), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_NON_FINITE);
  EXPECT_NE(s.message.find("Q_split"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("flat index 1"), std::string::npos) << s.message;
  Message pNan = partialGas({0, 3}, {0.5, 1.0}, 2);
  pNan.addArray<double>(fields::kHeatToParticles,
                        std::vector<double>{-std::numeric_limits<double>::infinity(), 2.5}, {2});
  s = validate(pNan, e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_NON_FINITE);
  EXPECT_NE(s.message.find("Q_split"), std::string::npos) << s.message;
  // float32 is refused like every coupling array.
  Message f32 = whole({}, {});
  f32.addArray<float>(fields::kHeatToParticles, std::vector<float>{1, 2, 3, 4}, {4});
  EXPECT_EQ(validate(f32, e).code, v1::ERROR_CODE_SHAPE);
  // No physical range: any finite value passes the gas ranges.
  const auto* spec = fields::findField(fields::kHeatToParticles);
  ASSERT_NE(spec, nullptr);
  EXPECT_EQ(spec->unit, "J/m3");
  EXPECT_EQ(spec->extent, v1::EXTENT_SCALAR);
}

// mom_p (v1.5): optional in Sources; when present float64 [rows, 3], finite.
TEST(ValidateSources, ReleasedMomentumIsOptionalThreePerCell) {
  const Expectation e = sourcesExpectation(); // 4 cells, 1 species
  const auto with = [](std::uint64_t rows, bool partial, std::vector<double> mom,
                       std::vector<std::uint64_t> shape) {
    Message m = sourcesWith(rows, partial, {}, {});
    m.addArray<double>(fields::kReleasedMomentum, mom, shape);
    return m;
  };
  std::vector<double> twelve(12, 0.25);
  twelve[5] = -3.5;
  Status s = validate(with(4, false, twelve, {4, 3}), e);
  EXPECT_TRUE(s.ok()) << s.toString();
  s = validate(with(2, true, {1, 2, 3, -4, -5, -6}, {2, 3}), e); // partial: listed cells
  EXPECT_TRUE(s.ok()) << s.toString();
  s = validate(with(4, false, twelve, {12}), e); // flat: refused
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);
  EXPECT_NE(s.message.find("'mom_p'"), std::string::npos) << s.message;
  s = validate(with(2, true, twelve, {4, 3}), e); // whole-grid rows in a partial Sources
  EXPECT_EQ(s.code, v1::ERROR_CODE_SHAPE);
  twelve[7] = std::nan("");
  s = validate(with(4, false, twelve, {4, 3}), e);
  EXPECT_EQ(s.code, v1::ERROR_CODE_NON_FINITE);
  EXPECT_NE(s.message.find("mom_p"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("row 2, column 1"), std::string::npos) << s.message;
  EXPECT_EQ(fields::findField(fields::kReleasedMomentum)->unit, "N/m3");
  EXPECT_EQ(fields::shapeOf(fields::kReleasedMomentum, 5, 2), (std::vector<std::uint64_t>{5, 3}));
}
