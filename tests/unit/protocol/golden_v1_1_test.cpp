// Golden v1.1 messages (protocol/golden/v1.1, written once by `coredem-golden-gen DIR 1`):
// decoded with the current code forever. v1.1 = v1.0 + explicit particle positions, the
// frozen-motion option and the chemistry fields of Configure; the Hello/Welcome/Reject carry
// minor 1. The v1.0 files keep decoding (golden_test.cpp) and carry no v1.1 fields.
#include <filesystem>

#include <gtest/gtest.h>

#include <coredem/protocol/message.h>
#include <coredem/protocol/multipart_file.h>
#include <coredem/protocol/validate.h>
#include <coredem/protocol/version.h>

using namespace coredem::protocol;
namespace v1 = coredem::v1;

namespace {

const std::filesystem::path kRoot = std::filesystem::path(COREDEM_GOLDEN_DIR);

Message load(const std::string& version, const std::string& name, v1::MessageType type) {
  Frames frames = readMultipartFile(kRoot / version / (name + ".cdmf"));
  Status s;
  Message m = Message::decode(frames, &s);
  EXPECT_TRUE(s.ok()) << version << "/" << name << ": " << s.toString();
  EXPECT_EQ(m.type(), type) << name;
  return m;
}

} // namespace

TEST(GoldenV1_1, EveryV10MessageTypeHasAV11FileThatDecodes) {
  for (const auto& entry : std::filesystem::directory_iterator(kRoot / "v1.0")) {
    const auto name = entry.path().filename();
    ASSERT_TRUE(std::filesystem::exists(kRoot / "v1.1" / name)) << name;
    Status s;
    Message m = Message::decode(readMultipartFile(kRoot / "v1.1" / name), &s);
    EXPECT_TRUE(s.ok()) << name << ": " << s.toString();
  }
}

TEST(GoldenV1_1, HandshakeCarriesMinorOne) {
  // This build speaks a later minor (version_test.cpp); the v1.1 files keep saying 1.1.
  Message h = load("v1.1", "hello", v1::MESSAGE_TYPE_HELLO);
  EXPECT_EQ(h.envelope().hello().protocol_major(), 1u);
  EXPECT_EQ(h.envelope().hello().protocol_minor(), 1u);
  Message w = load("v1.1", "welcome", v1::MESSAGE_TYPE_WELCOME);
  EXPECT_EQ(w.envelope().welcome().protocol_minor(), 1u);
  // A v1.1 peer and a v1.0 peer agree on 1.0 (the orchestrator then refuses chemistry cases).
  EXPECT_EQ(negotiate(Version{1, 1}, {1, 0}).agreed, (Version{1, 0}));
  EXPECT_EQ(negotiate(kProtocolVersion, {1, 0}).agreed, (Version{1, 0}));
  // Rank fields of v1.2 are absent from a v1.1 Hello (a v1.2 server reads one rank).
  EXPECT_EQ(h.envelope().hello().rank_count(), 0u);
}

TEST(GoldenV1_1, ConfigureCarriesExplicitPositionsAndChemistry) {
  Message m = load("v1.1", "configure", v1::MESSAGE_TYPE_CONFIGURE);
  const auto& c = m.envelope().configure();
  EXPECT_TRUE(validateConfigure(c).ok()) << validateConfigure(c).toString();
  // The v1.0 content is unchanged.
  EXPECT_EQ(c.case_name(), "golden");
  ASSERT_EQ(c.species_size(), 2);
  EXPECT_EQ(c.species(0).name(), "O2");
  ASSERT_EQ(c.particle_sets_size(), 2);
  EXPECT_EQ(c.particle_sets(0).name(), "carrier");
  // Explicit positions.
  const auto& p = c.particle_sets(1);
  EXPECT_EQ(p.name(), "placed");
  EXPECT_EQ(p.packing(), v1::PACKING_EXPLICIT);
  ASSERT_EQ(p.positions_size(), 2);
  EXPECT_EQ(p.positions(0).x(), 0.25);
  EXPECT_EQ(p.positions(1).x(), -0.25);
  EXPECT_EQ(p.positions(1).z(), 1.0);
  ASSERT_EQ(c.options_size(), 2);
  EXPECT_EQ(c.options(1).key(), "motion");
  EXPECT_EQ(c.options(1).value(), "frozen");
  // Chemistry.
  ASSERT_EQ(c.solid_species_size(), 3);
  EXPECT_EQ(c.solid_species(0).name(), "Fe2O3");
  EXPECT_EQ(c.solid_species(0).molar_mass(), 0.159688);
  EXPECT_EQ(c.solid_species(2).name(), "Al2O3");
  ASSERT_EQ(c.reactions_size(), 1);
  const auto& r = c.reactions(0);
  EXPECT_EQ(r.name(), "oxidation");
  ASSERT_EQ(r.terms_size(), 3);
  EXPECT_EQ(r.terms(0).species(), "Fe3O4");
  EXPECT_EQ(r.terms(0).nu(), -4.0);
  EXPECT_EQ(r.terms(2).nu(), 6.0);
  EXPECT_EQ(r.rate().law(), v1::RATE_LAW_ARRHENIUS);
  EXPECT_EQ(r.rate().a(), 2.5e-3);
  EXPECT_EQ(r.rate().beta(), 0.5);
  EXPECT_EQ(r.rate().activation_energy(), 8.0e4);
  EXPECT_EQ(r.rate().order_species(), "O2");
  EXPECT_EQ(r.rate().order(), 1.0);
  ASSERT_EQ(r.heat_case(), v1::Reaction::kHeatOfReaction);
  EXPECT_EQ(r.heat_of_reaction(), -4.75e5);
  ASSERT_TRUE(c.has_chemistry());
  const auto& ch = c.chemistry();
  EXPECT_FALSE(ch.clg().char_gasification());
  EXPECT_TRUE(ch.clg().oc_reduction());
  EXPECT_TRUE(ch.clg().wgs());
  EXPECT_EQ(ch.clg().wgs_equilibrium(), v1::WGS_EQUILIBRIUM_THERMODYNAMIC);
  EXPECT_EQ(ch.clg().char_stoichiometry(), v1::CHAR_STOICHIOMETRY_CARBON);
  ASSERT_EQ(ch.clg().kinetics_size(), 1);
  EXPECT_EQ(ch.clg().kinetics(0).name(), "k0_H2");
  EXPECT_EQ(ch.clg().kinetics(0).value(), 1.5e-3);
  ASSERT_TRUE(ch.has_removal_fraction());
  EXPECT_EQ(ch.removal_fraction(), 0.125);
  ASSERT_TRUE(ch.has_reaction_heat());
  EXPECT_FALSE(ch.reaction_heat());
}

TEST(GoldenV1_1, V10ConfigureHasNoV11Fields) {
  Message m = load("v1.0", "configure", v1::MESSAGE_TYPE_CONFIGURE);
  const auto& c = m.envelope().configure();
  EXPECT_EQ(c.solid_species_size(), 0);
  EXPECT_EQ(c.reactions_size(), 0);
  EXPECT_FALSE(c.has_chemistry());
  for (const auto& p : c.particle_sets())
    EXPECT_EQ(p.positions_size(), 0);
}
