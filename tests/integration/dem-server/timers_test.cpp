// coredem-dem --timers: the JSON report is valid JSON whose stage times add up to the session
// (every stage is named once; what is not named is "dem_other" or "server_other_s").
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "timers.h"

namespace {

TEST(DemTimers, JsonReportParsesAndAddsUp) {
  coredem::server::ExchangeTimes x;
  x.waitPeer = 0.5;
  x.validate = 0.01;
  x.unpack = 0.02;
  x.advance = 2.0;
  x.ledgers = 0.03;
  x.packSend = 0.04;
  x.checkpoint = 0.05;
  x.steps = 10;
  x.particleSubSteps = 12345;
  coredem::dem::StageTimes st;
  st.neighbour = 0.25;
  st.contact = 0.5;
  st.integrate = 0.125;
  st.rebuilds = 3;
  const std::string json = coredem::server::timersJson(x, st, 3.0, "session \"x\"", "cpu", 2);
  const YAML::Node n = YAML::Load(json);
  EXPECT_EQ(n["program"].as<std::string>(), "coredem-dem");
  EXPECT_EQ(n["session"].as<std::string>(), "session \"x\""); // escaped, not broken
  EXPECT_EQ(n["steps"].as<int>(), 10);
  EXPECT_EQ(n["particle_sub_steps"].as<int>(), 12345);
  EXPECT_EQ(n["rebuilds"].as<int>(), 3);
  double dem = 0.0;
  for (const auto& kv : n["dem_s"]) {
    dem += kv.second.as<double>();
  }
  EXPECT_NEAR(dem, x.advance, 1e-12);
  double ex = 0.0;
  for (const auto& kv : n["exchange_s"]) {
    ex += kv.second.as<double>();
  }
  EXPECT_NEAR(ex, n["exchange_total_s"].as<double>(), 1e-12);
  EXPECT_NEAR(n["advance_s"].as<double>() + ex + n["server_other_s"].as<double>(), 3.0, 1e-12);
}

} // namespace
