// Golden v1.3 messages (protocol/golden/v1.3, written once by `coredem-golden-gen DIR 3`):
// decoded with the current code forever. v1.3 = v1.2 + the Sources array Q_rad (the radiation
// heat the particles gave the gas, W/m3 of coupling cell; docs/protocol.md §3, §6).
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

Expectation sourcesExpectation() {
  Expectation e;
  e.types = {v1::MESSAGE_TYPE_SOURCES};
  e.cells = 2;
  e.species = 2;
  return e;
}

} // namespace

TEST(GoldenV1_3, EveryV12MessageTypeHasAV13FileThatDecodes) {
  for (const auto& entry : std::filesystem::directory_iterator(kRoot / "v1.2")) {
    const auto name = entry.path().filename();
    ASSERT_TRUE(std::filesystem::exists(kRoot / "v1.3" / name)) << name;
    Status s;
    Message m = Message::decode(readMultipartFile(kRoot / "v1.3" / name), &s);
    EXPECT_TRUE(s.ok()) << name << ": " << s.toString();
  }
}

TEST(GoldenV1_3, HelloWelcomeRejectCarryMinorThree) {
  Message h = load("v1.3", "hello");
  EXPECT_EQ(h.envelope().hello().protocol_major(), 1u);
  EXPECT_EQ(h.envelope().hello().protocol_minor(), 3u);
  EXPECT_EQ(h.envelope().hello().rank(), 1u); // still rank 1 of 2 (v1.2)
  EXPECT_EQ(h.envelope().hello().rank_count(), 2u);
  EXPECT_EQ(load("v1.3", "welcome").envelope().welcome().protocol_minor(), 3u);
  EXPECT_EQ(load("v1.3", "reject").envelope().reject().server_protocol_minor(), 3u);
}

TEST(GoldenV1_3, PartialSourcesCarryTheRadiationHeatOfTheListedCell) {
  Message m = load("v1.3", "sources");
  ASSERT_EQ(m.type(), v1::MESSAGE_TYPE_SOURCES);
  const auto& b = m.envelope().sources();
  EXPECT_TRUE(b.partial());
  EXPECT_EQ(b.touched_count(), 1u);
  const Status s = validate(m, sourcesExpectation());
  EXPECT_TRUE(s.ok()) << s.toString();
  EXPECT_EQ(m.findArray(fields::kTouchedCells)->as<std::int64_t>()[0], 1);
  const auto q = m.findArray(fields::kRadiationHeat);
  ASSERT_TRUE(q);
  EXPECT_EQ(q->dtype(), v1::DTYPE_FLOAT64);
  EXPECT_EQ(q->shape(), (std::vector<std::uint64_t>{1}));
  EXPECT_EQ(m.values<double>(fields::kRadiationHeat)[0], 2.0); // 0.25 (7 + 1) + 0.125 * 0
  // The seven required arrays are those of v1.2, with the same values.
  EXPECT_EQ(m.values<double>(fields::kVoidFraction)[0], 0.25);
  EXPECT_EQ(m.values<double>(fields::kHomogeneousHeat)[0], 1.75);
  EXPECT_EQ(m.arrayCount(), 9u); // cells + 7 required + Q_rad
}

// Sources of earlier versions carry no Q_rad and stay valid for a v1.3 reader.
TEST(GoldenV1_3, EarlierSourcesHaveNoRadiationHeat) {
  for (const char* version : {"v1.0", "v1.1", "v1.2"}) {
    Message m = load(version, "sources");
    EXPECT_FALSE(m.findArray(fields::kRadiationHeat)) << version;
    const Status s = validate(m, sourcesExpectation());
    EXPECT_TRUE(s.ok()) << version << ": " << s.toString();
  }
}

TEST(GoldenV1_3, OnlyTheSourcesChangedFromV12) {
  for (const auto& entry : std::filesystem::directory_iterator(kRoot / "v1.2")) {
    const std::string name = entry.path().stem().string();
    if (name == "sources" || name == "hello" || name == "welcome" || name == "reject") {
      continue;
    }
    EXPECT_EQ(readMultipartFile(kRoot / "v1.3" / (name + ".cdmf")),
              readMultipartFile(kRoot / "v1.2" / (name + ".cdmf")))
        << name;
  }
}
