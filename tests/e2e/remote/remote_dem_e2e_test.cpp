// End-to-end: the DEM server on a "remote node". coredem-dem runs in its own network namespace,
// bound to the namespace's end of a veth pair (a non-loopback address, so CURVE is required)
// with an allow-list of client keys; `coredem run` and its CFD participant (coredem-gas) reach
// it from the host over the veth link. Latency is emulated with `tc netem` where the kernel has
// it, else with coredem-relay started inside the namespace (bench/remote/relay.cpp), at round
// trips of 0 (the bare veth), 0.1, 1 and 10 ms. A client key not on the allow-list is still
// refused, at once and named, over the same link. Fails, saying why, where namespaces cannot be
// made (not root, no `ip`, a container without the capabilities): the remote-link test group is
// then opted out with -DCOREDEM_TEST_OPT_OUT=remote-link.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "coredem_e2e.h"
#include "netns_link.h"
#include "relay_trace.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

const fs::path kBin = COREDEM_BIN_DIR;
const fs::path kCases = COREDEM_E2E_CASES;

using coredem::e2e::NetnsLink;
using coredem::e2e::readAll;

constexpr int kDemPort = 5555;

constexpr const char* kOptOut = " (the remote-link test group needs root and iproute2: run the "
                                "tests as root, or configure with "
                                "-DCOREDEM_TEST_OPT_OUT=remote-link)";

class RemoteDemE2E : public coredem::e2e::RunFolderTest {
protected:
  RemoteDemE2E()
      : RunFolderTest(kBin, {"coredem", "coredem-dem", "coredem-gas", "coredem-relay"},
                      "coredem-e2e-remote") {}

  void SetUp() override {
    RunFolderTest::SetUp();
    if (HasFatalFailure()) {
      return;
    }
    const std::string why = NetnsLink::unavailableReason();
    ASSERT_TRUE(why.empty()) << "no emulated remote node: " << why << kOptOut;
    NetnsLink::cleanStale();
    link = std::make_unique<NetnsLink>();
    ASSERT_TRUE(link->ok()) << link->error();

    // Keys: the server's pair, alice's client pair (on the allow-list) and mallory's (not).
    const std::string dem = (kBin / "coredem-dem").string();
    for (const std::string& c : {dem + " --generate-curve-keys " + (dir / "server").string(),
                                 dem + " --generate-client-key " + (dir / "alice").string(),
                                 dem + " --generate-client-key " + (dir / "mallory").string()}) {
      ASSERT_EQ(std::system((c + " > /dev/null").c_str()), 0) << c;
    }
    coredem::e2e::writeAll(dir / "authorized_keys",
                           readAll(dir / "alice" / "client.public").substr(0, 40) + " alice\n");
    demEndpoint = "tcp://" + link->nsAddress + ":" + std::to_string(kDemPort);
    server = link->start(kBin / "coredem-dem",
                         {"--bind", demEndpoint, "--curve-keys", (dir / "server").string(),
                          "--client-keys", (dir / "authorized_keys").string(), "--threads", "1",
                          "--endpoint-file", (dir / "endpoint").string()},
                         dir / "server.log");
    const auto end = std::chrono::steady_clock::now() + 30s;
    while (!fs::exists(dir / "endpoint") && std::chrono::steady_clock::now() < end) {
      std::this_thread::sleep_for(10ms);
    }
    ASSERT_TRUE(fs::exists(dir / "endpoint")) << readAll(dir / "server.log");
  }

  void TearDown() override {
    link.reset(); // processes, veth and namespace go before the run folder
    RunFolderTest::TearDown();
  }

  /// The e2e restart case cut to 20 steps, reaching D at `endpoint` with `clientKey`.
  fs::path writeCase(const std::string& name, const std::string& endpoint,
                     const fs::path& clientKey) {
    std::string text = readAll(kCases / "restart" / "case.yaml");
    text.replace(text.find("  end: 0.1"), 10, "  end: 0.01"); // 20 steps
    text.replace(text.find("dem:\n"), 5,
                 "dem:\n  endpoint: " + endpoint +
                     "\n  server_key: " + (dir / "server" / "server.public").string() +
                     "\n  client_key: " + clientKey.string() + "\n");
    fs::create_directories(dir / name);
    coredem::e2e::writeAll(dir / name / "case.yaml", text);
    return dir / name;
  }

  int coredemRun(const fs::path& caseDir, const fs::path& out, const fs::path& log) {
    return coredem::e2e::waitExit(
        coredem::e2e::startProgram(
            kBin / "coredem", {"run", caseDir.string(), "--out", out.string(), "--no-plots"}, log),
        120s);
  }

  /// Starts a relay inside the namespace on `port` with `oneWayMs`; its log is `log`.
  void startRelay(int port, double oneWayMs, const fs::path& log) {
    link->start(kBin / "coredem-relay",
                {"--listen", link->nsAddress + ":" + std::to_string(port), "--target",
                 link->nsAddress + ":" + std::to_string(kDemPort), "--delay-ms",
                 std::to_string(oneWayMs), "--trace-chunks"},
                log);
    // Ready when it says so (it binds before logging).
    const auto end = std::chrono::steady_clock::now() + 20s;
    while (readAll(log).find("listening on") == std::string::npos &&
           std::chrono::steady_clock::now() < end) {
      std::this_thread::sleep_for(10ms);
    }
    ASSERT_NE(readAll(log).find("listening on"), std::string::npos) << readAll(log);
  }

  std::unique_ptr<NetnsLink> link;
  std::string demEndpoint;
  pid_t server = -1;
};

/// "key": value of a flat JSON object (NaN when absent).
double jsonNumber(const std::string& json, const std::string& key) {
  const auto k = json.find("\"" + key + "\"");
  if (k == std::string::npos) {
    return std::nan("");
  }
  return std::strtod(json.c_str() + json.find(':', k) + 1, nullptr);
}

/// The netem delays (ms) in `tc qdisc show` output ("delay 500us", "delay 5ms", "delay 1.5ms").
std::vector<double> netemDelaysMs(const std::string& qdiscs) {
  std::vector<double> out;
  const std::regex re("netem .*delay ([0-9.]+)(us|ms|s)\\b");
  for (std::sregex_iterator it(qdiscs.begin(), qdiscs.end(), re), end; it != end; ++it) {
    const double v = std::stod((*it)[1].str());
    const std::string unit = (*it)[2].str();
    out.push_back(unit == "us" ? v * 1e-3 : unit == "ms" ? v : v * 1e3);
  }
  return out;
}

/// Checks coredem-relay's --trace-chunks log: every chunk was due exactly `oneWayMs` after it
/// was read and written no earlier; returns the number of chunks each way ({up, down}).
std::pair<int, int> expectChunksHeld(const std::string& log, double oneWayMs) {
  const auto delayNs = std::chrono::duration_cast<std::chrono::nanoseconds>(
                           std::chrono::duration<double, std::milli>(oneWayMs))
                           .count();
  std::pair<int, int> n{0, 0};
  for (const auto& c : coredem::relay::tracedChunks(log)) {
    EXPECT_EQ(c.due - c.read, delayNs) << c.connection << " " << c.direction << " " << c.bytes;
    EXPECT_GE(c.written, c.due) << c.connection << " " << c.direction << " " << c.bytes;
    (c.direction == "up" ? n.first : n.second) += 1;
  }
  return n;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto i = text.find(what); i != std::string::npos; i = text.find(what, i + 1)) {
    ++n;
  }
  return n;
}

} // namespace

TEST_F(RemoteDemE2E, CoupledRunsReachTheDemServerOverTheLinkAtEachRoundTrip) {
  const bool netem = link->hasNetem();
  std::cout << "latency emulated with " << (netem ? "tc netem" : "coredem-relay (no netem qdisc)")
            << "\n";
  const fs::path alice = dir / "alice";
  for (const double rttMs : {0.0, 0.1, 1.0, 10.0}) {
    SCOPED_TRACE("round trip " + std::to_string(rttMs) + " ms");
    const std::string tag = "rtt" + std::to_string(int(rttMs * 1000)) + "us";
    std::string endpoint = demEndpoint;
    fs::path relayLog;
    if (netem) {
      ASSERT_TRUE(link->setNetemDelay(rttMs / 2));
    } else if (rttMs > 0.0) {
      const int port = 5600 + int(rttMs * 10);
      relayLog = dir / ("relay-" + tag + ".log");
      startRelay(port, rttMs / 2, relayLog);
      endpoint = "tcp://" + link->nsAddress + ":" + std::to_string(port);
    }
    const fs::path run = dir / ("run-" + tag), log = dir / (tag + ".log");
    ASSERT_EQ(coredemRun(writeCase(tag, endpoint, alice), run, log), 0)
        << readAll(log) << readAll(dir / "server.log") << readAll(relayLog);
    EXPECT_TRUE(fs::exists(run / "checkpoints/00000020/manifest.json"));
    // The link carried the round trip (checked by what the link reports, not by the clock):
    // netem's qdiscs on both ends hold the one-way delay, or the relay held every chunk for it,
    // and each of the 20 steps sent at least one request to D and got its reply through it.
    const double stepWall = jsonNumber(readAll(run / "logs" / "overhead.json"), "step_wall_s");
    std::cout << "round trip " << rttMs << " ms: " << stepWall * 1e3 << " ms per step\n";
    if (netem && rttMs > 0.0) {
      const std::string q = link->qdiscs();
      const auto delays = netemDelaysMs(q);
      ASSERT_EQ(delays.size(), 2u) << q;
      for (double d : delays) {
        EXPECT_NEAR(d, rttMs / 2, 1e-3) << q; // tc prints whole microseconds
      }
    }
    if (!relayLog.empty()) {
      // Both clients, the orchestrator and coredem-gas, came through the relay from the host's
      // end of the veth pair.
      const std::string text = readAll(relayLog);
      EXPECT_GE(count(text, "connection from " + link->hostAddress + ":"), 2u) << text;
      const auto [up, down] = expectChunksHeld(text, rttMs / 2);
      EXPECT_GE(up, 20) << text;
      EXPECT_GE(down, 20) << text;
    }
  }
  if (netem) {
    link->setNetemDelay(0.0);
  }
  // D saw the clients at the host's address of the link and admitted alice's key.
  const std::string serverLog = readAll(dir / "server.log");
  EXPECT_NE(serverLog.find(readAll(alice / "client.public").substr(0, 40)), std::string::npos)
      << serverLog;
  EXPECT_EQ(NetnsLink::stop(server), 0) << serverLog;
}

TEST_F(RemoteDemE2E, AKeyNotOnTheAllowListIsRefusedOverTheLink) {
  std::string endpoint = demEndpoint;
  if (link->hasNetem()) {
    ASSERT_TRUE(link->setNetemDelay(0.5));
  } else {
    startRelay(5610, 0.5, dir / "relay.log");
    endpoint = "tcp://" + link->nsAddress + ":5610";
  }
  const fs::path log = dir / "mallory.log";
  EXPECT_EQ(coredemRun(writeCase("mallory", endpoint, dir / "mallory"), dir / "run-mallory", log),
            1);
  const std::string text = readAll(log);
  EXPECT_NE(text.find("refused this client's CURVE key"), std::string::npos) << text;
  EXPECT_NE(text.find(readAll(dir / "mallory" / "client.public").substr(0, 40)), std::string::npos)
      << text;
  EXPECT_EQ(NetnsLink::stop(server), 0) << readAll(dir / "server.log");
}

// bench/remote/link.sh, the same set-up for benchmarks: `up` gives a `dem:` section that a case
// can use as it is, `down` leaves no namespace, veth or process behind.
class LinkScriptE2E : public coredem::e2e::RunFolderTest {
protected:
  LinkScriptE2E()
      : RunFolderTest(kBin, {"coredem", "coredem-dem", "coredem-gas", "coredem-relay"},
                      "coredem-e2e-link") {}
};

TEST_F(LinkScriptE2E, UpGivesAWorkingDemSectionAndDownRemovesEverything) {
  const std::string why = NetnsLink::unavailableReason();
  ASSERT_TRUE(why.empty()) << "no emulated remote node: " << why << kOptOut;
  const std::string name = "e2e" + std::to_string(::getpid());
  const std::string env = "BUILD_DIR=" + kBin.parent_path().string() +
                          " LINK_DIR=" + (dir / "links").string() + " DEM_ARGS='--threads 1' ";
  const std::string script = (fs::path(COREDEM_SOURCE_DIR) / "bench/remote/link.sh").string();
  struct Down { // the link goes, also when an assertion below fails
    std::string command;
    ~Down() { coredem::e2e::shell(command); }
  } down{env + script + " down " + name};
  std::string out;
  ASSERT_EQ(coredem::e2e::shell(env + script + " up " + name + " 2", &out), 0) << out;
  EXPECT_NE(out.find("round trip 2 ms"), std::string::npos) << out;
  const std::string dem = readAll(dir / "links" / name / "dem.yaml");
  ASSERT_NE(dem.find("endpoint: tcp://10.214."), std::string::npos) << dem;

  std::string text = readAll(kCases / "restart" / "case.yaml");
  text.replace(text.find("  end: 0.1"), 10, "  end: 0.01"); // 20 steps
  text.replace(text.find("dem:\n"), 5, dem);
  fs::create_directories(dir / "case");
  coredem::e2e::writeAll(dir / "case" / "case.yaml", text);
  const int rc =
      coredem::e2e::waitExit(coredem::e2e::startProgram(kBin / "coredem",
                                                        {"run", (dir / "case").string(), "--out",
                                                         (dir / "run").string(), "--no-plots"},
                                                        dir / "run.log"),
                             120s);
  EXPECT_EQ(rc, 0) << readAll(dir / "run.log") << readAll(dir / "links" / name / "dem.log");
  // The link has the 2 ms round trip it reported: netem's 1 ms on both ends, or the relay's
  // one-way delay of 1 ms with both clients through it (not measured by the clock).
  const std::string linkEnv = readAll(dir / "links" / name / "env");
  if (linkEnv.find("LINK_MODE=\"tc netem\"") != std::string::npos) {
    std::string q;
    coredem::e2e::shell("ip netns exec coredem-link-" + name + " tc qdisc show", &q);
    const auto delays = netemDelaysMs(q);
    ASSERT_EQ(delays.size(), 1u) << q;
    EXPECT_NEAR(delays[0], 1.0, 1e-3) << q;
  } else {
    ASSERT_NE(linkEnv.find("LINK_MODE=\"coredem-relay"), std::string::npos) << linkEnv;
    const std::string relayLog = readAll(dir / "links" / name / "relay.log");
    EXPECT_NE(relayLog.find("one-way delay 1 ms"), std::string::npos) << relayLog;
    EXPECT_GE(count(relayLog, "connection from "), 2u) << relayLog;
  }

  ASSERT_EQ(coredem::e2e::shell(env + script + " down " + name, &out), 0) << out;
  std::string list;
  coredem::e2e::shell("ip netns list", &list);
  EXPECT_EQ(list.find("coredem-link-" + name), std::string::npos) << list;
  EXPECT_FALSE(fs::exists(dir / "links" / name));
}
