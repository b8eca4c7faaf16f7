// Golden v1.6 messages (protocol/golden/v1.6, written once by `coredem-golden-gen DIR 6`):
// decoded with the current code forever. v1.6 = v1.5 + the contact materials in Configure:
// Material.youngs_modulus and .poisson_ratio (the Hertz–Mindlin law), Configure.material_pairs
// and the walls' material_id (Box, Plane, RevolvedWall, MeshWall); docs/protocol.md §3.
#include <filesystem>

#include <gtest/gtest.h>

#include <coredem/protocol/message.h>
#include <coredem/protocol/multipart_file.h>
#include <coredem/protocol/version.h>

using namespace coredem::protocol;
namespace v1 = coredem::v1;

namespace {

const std::filesystem::path kRoot = std::filesystem::path(COREDEM_GOLDEN_DIR);

Message load(const std::string& version, const std::string& name) {
  Frames frames = readMultipartFile(kRoot / version / (name + ".cdmf"));
  Status s;
  Message m = Message::decode(frames, &s);
  EXPECT_TRUE(s.ok()) << version << "/" << name << ": " << s.toString();
  return m;
}

} // namespace

TEST(GoldenV1_6, EveryV15MessageTypeHasAV16FileThatDecodes) {
  for (const auto& entry : std::filesystem::directory_iterator(kRoot / "v1.5")) {
    const auto name = entry.path().filename();
    ASSERT_TRUE(std::filesystem::exists(kRoot / "v1.6" / name)) << name;
    Status s;
    Message m = Message::decode(readMultipartFile(kRoot / "v1.6" / name), &s);
    EXPECT_TRUE(s.ok()) << name << ": " << s.toString();
  }
}

TEST(GoldenV1_6, HelloWelcomeRejectCarryMinorSix) {
  EXPECT_EQ(kMinorContactMaterials, 6u);
  EXPECT_EQ(load("v1.6", "hello").envelope().hello().protocol_minor(), 6u);
  EXPECT_EQ(load("v1.6", "welcome").envelope().welcome().protocol_minor(), 6u);
  EXPECT_EQ(load("v1.6", "reject").envelope().reject().server_protocol_minor(), 6u);
}

TEST(GoldenV1_6, ConfigureCarriesTheContactMaterials) {
  const Message m = load("v1.6", "configure");
  const v1::Configure& c = m.envelope().configure();
  ASSERT_EQ(c.materials_size(), 2);
  EXPECT_TRUE(c.materials(0).has_youngs_modulus());
  EXPECT_EQ(c.materials(0).youngs_modulus(), 1.5e8);
  EXPECT_EQ(c.materials(0).poisson_ratio(), 0.25);
  EXPECT_EQ(c.materials(1).id(), 2u);
  EXPECT_EQ(c.materials(1).name(), "steel");
  EXPECT_EQ(c.materials(1).youngs_modulus(), 2e11);
  EXPECT_FALSE(c.materials(1).has_poisson_ratio()); // the default 0.3
  EXPECT_EQ(c.materials(1).friction(), 0.0);
  ASSERT_EQ(c.material_pairs_size(), 1);
  EXPECT_EQ(c.material_pairs(0).material_a(), 1u);
  EXPECT_EQ(c.material_pairs(0).material_b(), 2u);
  EXPECT_EQ(c.material_pairs(0).e_n(), 0.5);
  EXPECT_FALSE(c.material_pairs(0).has_friction()); // the mixed value
  EXPECT_EQ(c.walls().box().material_id(), 2u);
  EXPECT_EQ(c.walls().planes(0).material_id(), 1u);
  EXPECT_EQ(c.walls().revolved(0).material_id(), 2u);
  EXPECT_FALSE(c.walls().revolved(1).has_material_id()); // the particle's own
  EXPECT_EQ(c.walls().meshes(0).material_id(), 1u);
  EXPECT_EQ(c.walls().material_id(), 1u); // the walls' heat conduction material, as before
}

// A v1.5 Configure has none of the new fields: a v1.6 server reads today's behaviour from it
// (walls with the particle's own material, the law's mixing for every pair, no E).
TEST(GoldenV1_6, EarlierConfiguresHaveNoContactMaterials) {
  for (const char* version : {"v1.0", "v1.4", "v1.5"}) {
    const Message m = load(version, "configure");
    const v1::Configure& c = m.envelope().configure();
    EXPECT_EQ(c.material_pairs_size(), 0) << version;
    for (const auto& m : c.materials()) {
      EXPECT_FALSE(m.has_youngs_modulus()) << version;
      EXPECT_FALSE(m.has_poisson_ratio()) << version;
    }
    EXPECT_FALSE(c.walls().box().has_material_id()) << version;
    for (const auto& p : c.walls().planes())
      EXPECT_FALSE(p.has_material_id()) << version;
    for (const auto& r : c.walls().revolved())
      EXPECT_FALSE(r.has_material_id()) << version;
    for (const auto& m : c.walls().meshes())
      EXPECT_FALSE(m.has_material_id()) << version;
  }
}

TEST(GoldenV1_6, OnlyTheSessionMessagesChangedFromV15) {
  for (const auto& entry : std::filesystem::directory_iterator(kRoot / "v1.5")) {
    const std::string name = entry.path().stem().string();
    if (name == "configure" || name == "hello" || name == "welcome" || name == "reject") {
      continue;
    }
    EXPECT_EQ(readMultipartFile(kRoot / "v1.6" / (name + ".cdmf")),
              readMultipartFile(kRoot / "v1.5" / (name + ".cdmf")))
        << name;
  }
}
