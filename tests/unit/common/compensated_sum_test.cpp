// CompensatedSum (Kahan) and parseSwitch.
#include <cmath>
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include <coredem/common/compensated_sum.h>
#include <coredem/common/switch.h>
#include <coredem/common/version.h>

namespace {

// 10^6 additions of 1e-6: the naive sum drifts by 7.9e-12, the compensated one stays
// within 2 ulp of 1 (4.5e-16) once the carry is taken into account.
TEST(CompensatedSum, ManyTinyIncrementsDoNotDrift) {
  coredem::CompensatedSum s;
  double naive = 0.0;
  for (int i = 0; i < 1000000; ++i) {
    s.add(1e-6);
    naive += 1e-6;
  }
  EXPECT_GT(std::fabs(naive - 1.0), 1e-12); // the effect being fixed is real (7.9e-12)
  EXPECT_NEAR(s.value() - s.compensation(), 1.0, 4.5e-16);
}

// Restarting from (value, compensation) continues bit for bit.
TEST(CompensatedSum, RestartFromValueAndCarryIsBitwise) {
  coredem::CompensatedSum straight;
  coredem::CompensatedSum first;
  for (int i = 0; i < 1000; ++i) {
    straight.add(0.1 * i + 1e-9);
    first.add(0.1 * i + 1e-9);
  }
  coredem::CompensatedSum resumed(first.value(), first.compensation());
  for (int i = 0; i < 1000; ++i) {
    straight += 1.0 / (i + 3);
    resumed += 1.0 / (i + 3);
  }
  EXPECT_EQ(std::memcmp(&straight, &resumed, sizeof straight), 0);
}

TEST(Switch, AcceptsOneSpellingSetAndRefusesTheRest) {
  for (const char* on : {"on", "true", "yes", "1"}) {
    EXPECT_EQ(coredem::parseSwitch(on), true) << on;
  }
  for (const char* off : {"off", "false", "no", "0"}) {
    EXPECT_EQ(coredem::parseSwitch(off), false) << off;
  }
  for (const char* bad : {"", "On", "enabled", "2", "of"}) {
    EXPECT_FALSE(coredem::parseSwitch(bad).has_value()) << bad;
  }
}

TEST(Version, ComesFromTheProject) {
  const std::string v = coredem::kVersion;
  EXPECT_EQ(v, std::to_string(coredem::kVersionMajor) + "." +
                   std::to_string(coredem::kVersionMinor) + "." +
                   std::to_string(coredem::kVersionPatch));
}

} // namespace
