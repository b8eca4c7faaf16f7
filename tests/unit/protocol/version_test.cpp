// Version negotiation rule (docs/protocol.md).
#include <gtest/gtest.h>

#include <coredem/protocol/version.h>

using namespace coredem::protocol;

TEST(Version, SameMajorAcceptsWithTheLowerMinor) {
  Negotiation n = negotiate({1, 0}, {1, 3});
  EXPECT_TRUE(n.accepted);
  EXPECT_EQ(n.agreed, (Version{1, 0}));
  EXPECT_TRUE(n.status.ok());

  n = negotiate({1, 4}, {1, 2});
  EXPECT_TRUE(n.accepted);
  EXPECT_EQ(n.agreed, (Version{1, 2}));
}

TEST(Version, OtherMajorIsRejectedNamingBothVersions) {
  Negotiation n = negotiate({1, 0}, {2, 5});
  EXPECT_FALSE(n.accepted);
  EXPECT_EQ(n.status.code, coredem::v1::ERROR_CODE_VERSION);
  EXPECT_NE(n.status.message.find("1.0"), std::string::npos) << n.status.message;
  EXPECT_NE(n.status.message.find("2.5"), std::string::npos) << n.status.message;

  n = negotiate({1, 0}, {0, 9});
  EXPECT_FALSE(n.accepted);
  EXPECT_NE(n.status.message.find("0.9"), std::string::npos);
}

TEST(Version, ThisBuildSpeaksOneDotSix) {
  // v1.1: chemistry in Configure (solid species, reactions, chemistry), explicit positions.
  // v1.2: decomposed CFD (rank identity in Hello, partial GasFields/Sources), fluid_fraction.
  // v1.3: the Sources array Q_rad (radiation heat the particles gave the gas).
  // v1.4: cylinder, cone and triangle-mesh walls in Configure (Walls.revolved, Walls.meshes).
  // v1.5: the Sources array mom_p (momentum of the released mass) and the GasFields array
  //       Q_split (heat for the particles).
  // v1.6: contact materials (Material.youngs_modulus, .poisson_ratio, Configure.material_pairs,
  //       the walls' material_id).
  EXPECT_EQ(kProtocolVersion, (Version{1, 6}));
  EXPECT_EQ(kProtocolVersion.toString(), "1.6");
  EXPECT_EQ(kMinorDecomposed, 2u);
  EXPECT_EQ(kMinorRadiation, 3u);
  EXPECT_EQ(kMinorWallShapes, 4u);
  EXPECT_EQ(kMinorReleasedMomentum, 5u);
  EXPECT_EQ(kMinorHeatToParticles, 5u);
  EXPECT_EQ(kMinorContactMaterials, 6u);
  // With a v1.0 to v1.5 peer the agreed version is that peer's.
  EXPECT_EQ(negotiate(kProtocolVersion, {1, 0}).agreed, (Version{1, 0}));
  EXPECT_EQ(negotiate(kProtocolVersion, {1, 1}).agreed, (Version{1, 1}));
  EXPECT_EQ(negotiate(kProtocolVersion, {1, 2}).agreed, (Version{1, 2}));
  EXPECT_EQ(negotiate(kProtocolVersion, {1, 3}).agreed, (Version{1, 3}));
  EXPECT_EQ(negotiate(kProtocolVersion, {1, 4}).agreed, (Version{1, 4}));
  EXPECT_EQ(negotiate(kProtocolVersion, {1, 5}).agreed, (Version{1, 5}));
  EXPECT_EQ(negotiate(kProtocolVersion, {1, 6}).agreed, (Version{1, 6}));
  EXPECT_EQ(negotiate(kProtocolVersion, {1, 9}).agreed, (Version{1, 6})); // a newer client
  EXPECT_EQ(negotiate({1, 5}, kProtocolVersion).agreed, (Version{1, 5})); // a 1.5 server
}
