// Golden v1.4 messages (protocol/golden/v1.4, written once by `coredem-golden-gen DIR 4`):
// decoded with the current code forever. v1.4 = v1.3 + the Configure walls of other shapes:
// cylinders and cones (Walls.revolved) and triangle meshes (Walls.meshes); docs/protocol.md §2, §6.
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

Message load(const std::string& version, const std::string& name) {
  Frames frames = readMultipartFile(kRoot / version / (name + ".cdmf"));
  Status s;
  Message m = Message::decode(frames, &s);
  EXPECT_TRUE(s.ok()) << version << "/" << name << ": " << s.toString();
  return m;
}

} // namespace

TEST(GoldenV1_4, EveryV13MessageTypeHasAV14FileThatDecodes) {
  for (const auto& entry : std::filesystem::directory_iterator(kRoot / "v1.3")) {
    const auto name = entry.path().filename();
    ASSERT_TRUE(std::filesystem::exists(kRoot / "v1.4" / name)) << name;
    Status s;
    Message m = Message::decode(readMultipartFile(kRoot / "v1.4" / name), &s);
    EXPECT_TRUE(s.ok()) << name << ": " << s.toString();
  }
}

TEST(GoldenV1_4, HelloWelcomeRejectCarryMinorFour) {
  EXPECT_EQ(kMinorWallShapes, 4u);
  Message h = load("v1.4", "hello");
  EXPECT_EQ(h.envelope().hello().protocol_major(), 1u);
  EXPECT_EQ(h.envelope().hello().protocol_minor(), 4u);
  EXPECT_EQ(load("v1.4", "welcome").envelope().welcome().protocol_minor(), 4u);
  EXPECT_EQ(load("v1.4", "reject").envelope().reject().server_protocol_minor(), 4u);
}

TEST(GoldenV1_4, ConfigureCarriesACylinderAConeAndAMesh) {
  Message m = load("v1.4", "configure");
  ASSERT_EQ(m.type(), v1::MESSAGE_TYPE_CONFIGURE);
  const v1::Configure& c = m.envelope().configure();
  EXPECT_TRUE(validateConfigure(c).ok()) << validateConfigure(c).toString();
  const v1::Walls& w = c.walls();
  // The v1.0 walls are unchanged.
  EXPECT_EQ(w.box().max().z(), 2.25);
  ASSERT_EQ(w.planes_size(), 1);
  ASSERT_EQ(w.revolved_size(), 2);
  const v1::RevolvedWall& cyl = w.revolved(0);
  EXPECT_FALSE(cyl.cone());
  EXPECT_EQ(cyl.point().y(), 0.5);
  EXPECT_EQ(cyl.point().z(), 0.25);
  EXPECT_EQ(cyl.axis().z(), 1.0);
  EXPECT_EQ(cyl.radius_start(), 0.5);
  EXPECT_EQ(cyl.radius_end(), 0.5);
  EXPECT_EQ(cyl.start(), 0.0);
  EXPECT_EQ(cyl.end(), 2.0);
  EXPECT_FALSE(cyl.infinite());
  EXPECT_EQ(cyl.side(), v1::WALL_SIDE_INSIDE);
  EXPECT_TRUE(cyl.cap_start());
  EXPECT_FALSE(cyl.cap_end());
  const v1::RevolvedWall& cone = w.revolved(1);
  EXPECT_TRUE(cone.cone());
  EXPECT_EQ(cone.axis().z(), 2.0);
  EXPECT_EQ(cone.radius_start(), 0.125);
  EXPECT_EQ(cone.radius_end(), 0.375);
  EXPECT_EQ(cone.start(), 0.5);
  EXPECT_EQ(cone.end(), 1.5);
  EXPECT_EQ(cone.side(), v1::WALL_SIDE_OUTSIDE);
  EXPECT_FALSE(cone.cap_start());
  EXPECT_TRUE(cone.cap_end());
  ASSERT_EQ(w.meshes_size(), 1);
  const v1::MeshWall& mesh = w.meshes(0);
  EXPECT_EQ(mesh.name(), "plate.stl");
  ASSERT_EQ(mesh.vertices_size(), 12);
  EXPECT_EQ(mesh.vertices(0), -0.5);
  EXPECT_EQ(mesh.vertices(7), 1.0);
  EXPECT_EQ(mesh.vertices(11), 1.0);
  ASSERT_EQ(mesh.triangles_size(), 6);
  EXPECT_EQ(mesh.triangles(4), 2);
  EXPECT_EQ(mesh.triangles(5), 3);
  // Everything else of the Configure is v1.3's.
  v1::Configure rest = c;
  rest.mutable_walls()->clear_revolved();
  rest.mutable_walls()->clear_meshes();
  EXPECT_EQ(rest.SerializeAsString(),
            load("v1.3", "configure").envelope().configure().SerializeAsString());
}

// Configures of earlier versions have no such walls.
TEST(GoldenV1_4, EarlierConfiguresHaveOnlyBoxAndPlanes) {
  for (const char* version : {"v1.0", "v1.1", "v1.2", "v1.3"}) {
    const v1::Configure& c = load(version, "configure").envelope().configure();
    EXPECT_EQ(c.walls().revolved_size(), 0) << version;
    EXPECT_EQ(c.walls().meshes_size(), 0) << version;
  }
}

TEST(GoldenV1_4, OnlyTheConfigureChangedFromV13) {
  for (const auto& entry : std::filesystem::directory_iterator(kRoot / "v1.3")) {
    const std::string name = entry.path().stem().string();
    if (name == "configure" || name == "hello" || name == "welcome" || name == "reject") {
      continue;
    }
    EXPECT_EQ(readMultipartFile(kRoot / "v1.4" / (name + ".cdmf")),
              readMultipartFile(kRoot / "v1.3" / (name + ".cdmf")))
        << name;
  }
}
