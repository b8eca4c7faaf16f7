// Golden v1.2 messages (protocol/golden/v1.2, written once by `coredem-golden-gen DIR 2`):
// decoded with the current code forever. v1.2 = v1.1 + rank identity in Hello and the partial
// GasFields/Sources of a decomposed CFD participant (docs/protocol.md "Decomposed CFD").
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

Message load(const std::string& name, v1::MessageType type) {
  Frames frames = readMultipartFile(kRoot / "v1.2" / (name + ".cdmf"));
  Status s;
  Message m = Message::decode(frames, &s);
  EXPECT_TRUE(s.ok()) << name << ": " << s.toString();
  EXPECT_EQ(m.type(), type) << name;
  return m;
}

Expectation configured(v1::MessageType type) {
  Expectation e;
  e.types = {type};
  e.cells = 2;
  e.species = 2;
  return e;
}

} // namespace

TEST(GoldenV1_2, EveryV11MessageTypeHasAV12FileThatDecodes) {
  for (const auto& entry : std::filesystem::directory_iterator(kRoot / "v1.1")) {
    const auto name = entry.path().filename();
    ASSERT_TRUE(std::filesystem::exists(kRoot / "v1.2" / name)) << name;
    Status s;
    Message m = Message::decode(readMultipartFile(kRoot / "v1.2" / name), &s);
    EXPECT_TRUE(s.ok()) << name << ": " << s.toString();
  }
}

TEST(GoldenV1_2, HelloCarriesMinorTwoAndTheRank) {
  Message h = load("hello", v1::MESSAGE_TYPE_HELLO);
  EXPECT_EQ(h.envelope().hello().protocol_major(), 1u);
  EXPECT_EQ(h.envelope().hello().protocol_minor(), 2u);
  EXPECT_EQ(h.envelope().hello().role(), v1::ROLE_CFD);
  EXPECT_EQ(h.envelope().hello().rank(), 1u);
  EXPECT_EQ(h.envelope().hello().rank_count(), 2u);
  EXPECT_EQ(load("welcome", v1::MESSAGE_TYPE_WELCOME).envelope().welcome().protocol_minor(), 2u);
  EXPECT_EQ(load("reject", v1::MESSAGE_TYPE_REJECT).envelope().reject().server_protocol_minor(),
            2u);
}

TEST(GoldenV1_2, PartialGasFieldsListOneCellWithItsFluidVolume) {
  Message m = load("gas_fields", v1::MESSAGE_TYPE_GAS_FIELDS);
  const auto& b = m.envelope().gas_fields();
  EXPECT_TRUE(b.partial());
  EXPECT_EQ(b.touched_count(), 1u);
  EXPECT_EQ(b.cell_count(), 2u);
  const Status s = validate(m, configured(v1::MESSAGE_TYPE_GAS_FIELDS));
  EXPECT_TRUE(s.ok()) << s.toString();
  const auto cells = m.findArray(fields::kTouchedCells);
  ASSERT_TRUE(cells);
  ASSERT_EQ(cells->as<std::int64_t>().size(), 1u);
  EXPECT_EQ(cells->as<std::int64_t>()[0], 1);
  ASSERT_EQ(m.values<double>(fields::kFluidVolume).size(), 1u);
  EXPECT_EQ(m.values<double>(fields::kFluidVolume)[0], 0.125);
  // Field f, flat index i: 0.25 (f + 1) + 0.125 i; one row each.
  EXPECT_EQ(m.values<double>(fields::kGasVelocity).size(), 3u);
  EXPECT_EQ(m.values<double>(fields::kGasVelocity)[2], 0.5);
  EXPECT_EQ(m.values<double>(fields::kGasTemperature)[0], 0.75);
  EXPECT_EQ(m.values<double>(fields::kGasMassFractions).size(), 2u);
  EXPECT_EQ(m.values<double>(fields::kGasMassFractions)[1], 2.125);
}

TEST(GoldenV1_2, PartialSourcesAnswerTheListedCell) {
  Message m = load("sources", v1::MESSAGE_TYPE_SOURCES);
  const auto& b = m.envelope().sources();
  EXPECT_TRUE(b.partial());
  EXPECT_EQ(b.touched_count(), 1u);
  EXPECT_EQ(b.substeps(), 50u);
  const Status s = validate(m, configured(v1::MESSAGE_TYPE_SOURCES));
  EXPECT_TRUE(s.ok()) << s.toString();
  EXPECT_EQ(m.findArray(fields::kTouchedCells)->as<std::int64_t>()[0], 1);
  EXPECT_EQ(m.values<double>(fields::kVoidFraction).size(), 1u);
  EXPECT_EQ(m.values<double>(fields::kVoidFraction)[0], 0.25);
  EXPECT_EQ(m.values<double>(fields::kDragCoefficientTimesUs)[1], 0.875); // field 2, index 1
}

// A v1.2 reader of a v1.1 GasFields sees a whole-grid message (partial false).
TEST(GoldenV1_2, V11GasFieldsReadAsWholeGrid) {
  Status s;
  Message m = Message::decode(readMultipartFile(kRoot / "v1.1" / "gas_fields.cdmf"), &s);
  ASSERT_TRUE(s.ok());
  EXPECT_FALSE(m.envelope().gas_fields().partial());
  EXPECT_TRUE(validate(m, configured(v1::MESSAGE_TYPE_GAS_FIELDS)).ok());
}
