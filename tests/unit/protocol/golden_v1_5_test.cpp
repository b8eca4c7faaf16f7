// Golden v1.5 messages (protocol/golden/v1.5, written once by `coredem-golden-gen DIR 5`):
// decoded with the current code forever. v1.5 = v1.4 + the GasFields array Q_split (heat the gas
// removed beyond what the DEM booked, for the cell's particles, J/m3 of coupling cell, extensive in
// a partial GasFields) and the Sources array mom_p (momentum of the mass the particles give the
// gas, N/m3); docs/protocol.md §3, §6.
#include <filesystem>

#include <gtest/gtest.h>

#include <coredem/protocol/fields.h>
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

Expectation fieldsExpectation(v1::MessageType type) {
  Expectation e;
  e.types = {type};
  e.cells = 2;
  e.species = 2;
  return e;
}

} // namespace

TEST(GoldenV1_5, EveryV14MessageTypeHasAV15FileThatDecodes) {
  for (const auto& entry : std::filesystem::directory_iterator(kRoot / "v1.4")) {
    const auto name = entry.path().filename();
    ASSERT_TRUE(std::filesystem::exists(kRoot / "v1.5" / name)) << name;
    Status s;
    Message m = Message::decode(readMultipartFile(kRoot / "v1.5" / name), &s);
    EXPECT_TRUE(s.ok()) << name << ": " << s.toString();
  }
}

TEST(GoldenV1_5, HelloWelcomeRejectCarryMinorFive) {
  EXPECT_EQ(kMinorReleasedMomentum, 5u);
  EXPECT_EQ(kMinorHeatToParticles, 5u);
  Message h = load("v1.5", "hello");
  EXPECT_EQ(h.envelope().hello().protocol_major(), 1u);
  EXPECT_EQ(h.envelope().hello().protocol_minor(), 5u);
  EXPECT_EQ(h.envelope().hello().rank(), 1u); // still rank 1 of 2 (v1.2)
  EXPECT_EQ(h.envelope().hello().rank_count(), 2u);
  EXPECT_EQ(load("v1.5", "welcome").envelope().welcome().protocol_minor(), 5u);
  EXPECT_EQ(load("v1.5", "reject").envelope().reject().server_protocol_minor(), 5u);
}

TEST(GoldenV1_5, PartialGasFieldsCarryTheHeatForTheParticlesOfTheListedCell) {
  Message m = load("v1.5", "gas_fields");
  ASSERT_EQ(m.type(), v1::MESSAGE_TYPE_GAS_FIELDS);
  const auto& b = m.envelope().gas_fields();
  EXPECT_TRUE(b.partial());
  EXPECT_EQ(b.touched_count(), 1u);
  const Status s = validate(m, fieldsExpectation(v1::MESSAGE_TYPE_GAS_FIELDS));
  EXPECT_TRUE(s.ok()) << s.toString();
  EXPECT_EQ(m.findArray(fields::kTouchedCells)->as<std::int64_t>()[0], 1);
  const auto q = m.findArray(fields::kHeatToParticles);
  ASSERT_TRUE(q);
  EXPECT_EQ(q->dtype(), v1::DTYPE_FLOAT64);
  EXPECT_EQ(q->shape(), (std::vector<std::uint64_t>{1}));
  EXPECT_EQ(m.values<double>(fields::kHeatToParticles)[0], -2.25); // −(0.25 (8 + 1) + 0.125 · 0)
  // The required arrays and the fluid volume are those of v1.2..v1.4.
  EXPECT_EQ(m.values<double>(fields::kFluidVolume)[0], 0.125);
  EXPECT_EQ(m.values<double>(fields::kGasTemperature)[0], 0.75);
  EXPECT_EQ(m.arrayCount(), 11u); // cells, fluid_volume, 8 required, Q_split
}

TEST(GoldenV1_5, PartialSourcesCarryTheMomentumOfTheReleasedMass) {
  Message m = load("v1.5", "sources");
  ASSERT_EQ(m.type(), v1::MESSAGE_TYPE_SOURCES);
  const auto& b = m.envelope().sources();
  EXPECT_TRUE(b.partial());
  EXPECT_EQ(b.touched_count(), 1u);
  const Status s = validate(m, fieldsExpectation(v1::MESSAGE_TYPE_SOURCES));
  EXPECT_TRUE(s.ok()) << s.toString();
  const auto p = m.findArray(fields::kReleasedMomentum);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->dtype(), v1::DTYPE_FLOAT64);
  EXPECT_EQ(p->shape(), (std::vector<std::uint64_t>{1, 3}));
  const auto v = m.values<double>(fields::kReleasedMomentum);
  ASSERT_EQ(v.size(), 3u);
  EXPECT_EQ(v[0], 2.25); // 0.25 (8 + 1) + 0.125 i
  EXPECT_EQ(v[1], 2.375);
  EXPECT_EQ(v[2], 2.5);
  EXPECT_EQ(m.values<double>(fields::kRadiationHeat)[0], 2.0); // v1.3's Q_rad, unchanged
  EXPECT_EQ(m.arrayCount(), 10u);                              // cells + 7 required + Q_rad + mom_p
}

// GasFields and Sources of earlier versions carry neither array and stay valid for a v1.5 reader.
TEST(GoldenV1_5, EarlierMessagesHaveNeitherArray) {
  for (const char* version : {"v1.0", "v1.1", "v1.2", "v1.3", "v1.4"}) {
    Message g = load(version, "gas_fields");
    EXPECT_FALSE(g.findArray(fields::kHeatToParticles)) << version;
    Status s = validate(g, fieldsExpectation(v1::MESSAGE_TYPE_GAS_FIELDS));
    EXPECT_TRUE(s.ok()) << version << ": " << s.toString();
    Message m = load(version, "sources");
    EXPECT_FALSE(m.findArray(fields::kReleasedMomentum)) << version;
    s = validate(m, fieldsExpectation(v1::MESSAGE_TYPE_SOURCES));
    EXPECT_TRUE(s.ok()) << version << ": " << s.toString();
  }
}

TEST(GoldenV1_5, OnlyTheExchangeMessagesChangedFromV14) {
  for (const auto& entry : std::filesystem::directory_iterator(kRoot / "v1.4")) {
    const std::string name = entry.path().stem().string();
    if (name == "gas_fields" || name == "sources" || name == "hello" || name == "welcome" ||
        name == "reject") {
      continue;
    }
    EXPECT_EQ(readMultipartFile(kRoot / "v1.5" / (name + ".cdmf")),
              readMultipartFile(kRoot / "v1.4" / (name + ".cdmf")))
        << name;
  }
}

// Apart from the new array, the v1.5 exchange messages are v1.4's.
TEST(GoldenV1_5, TheExchangeMessagesAreV14sPlusTheNewArray) {
  for (const auto& [name, array] : {std::pair{"gas_fields", fields::kHeatToParticles},
                                    std::pair{"sources", fields::kReleasedMomentum}}) {
    const Message now = load("v1.5", name);
    const Message before = load("v1.4", name);
    ASSERT_EQ(now.arrayCount(), before.arrayCount() + 1) << name;
    for (std::size_t i = 0; i < before.arrayCount(); ++i) {
      const auto a = before.array(i);
      const auto b = now.findArray(a.name());
      ASSERT_TRUE(b) << name << ": " << a.name();
      EXPECT_EQ(b->shape(), a.shape()) << name << ": " << a.name();
      EXPECT_TRUE(std::equal(a.bytes.begin(), a.bytes.end(), b->bytes.begin(), b->bytes.end()))
          << name << ": " << a.name();
    }
    EXPECT_TRUE(now.findArray(array)) << name;
  }
}
