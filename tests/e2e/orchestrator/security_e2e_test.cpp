// End-to-end: client authentication of a remote DEM server. coredem-dem runs with CURVE and an
// allow-list of client keys (--client-keys); `coredem run` with dem.client_key (the user's
// persistent pair) is admitted, and so is its CFD participant, which gets the key as a file
// path (COREDEM_DEM_CLIENT_KEY_FILE); a case without a listed key is refused at once, named.
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include "coredem_e2e.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

const fs::path kBin = COREDEM_BIN_DIR;
const fs::path kCases = COREDEM_E2E_CASES;

using coredem::e2e::readAll;

class SecurityE2E : public coredem::e2e::RunFolderTest {
protected:
  SecurityE2E()
      : RunFolderTest(kBin, {"coredem", "coredem-dem", "coredem-gas"}, "coredem-e2e-security") {}
};

int run(const std::string& command) {
  return std::system((command + " > /dev/null").c_str());
}

} // namespace

TEST_F(SecurityE2E, ClientKeysAreLoadedByTheOrchestratorAndTheCfdParticipant) {
  const std::string dem = (kBin / "coredem-dem").string();
  ASSERT_EQ(run(dem + " --generate-curve-keys " + (dir / "server").string()), 0);
  ASSERT_EQ(run(dem + " --generate-client-key " + (dir / "alice").string()), 0);
  ASSERT_EQ(run(dem + " --generate-client-key " + (dir / "mallory").string()), 0);
  {
    std::ofstream allow(dir / "authorized_keys");
    allow << readAll(dir / "alice" / "client.public") << "\n";
  }
  const std::vector<std::string> args = {"--bind",          "tcp://127.0.0.1:*",
                                         "--curve-keys",    (dir / "server").string(),
                                         "--client-keys",   (dir / "authorized_keys").string(),
                                         "--threads",       "1",
                                         "--endpoint-file", (dir / "endpoint").string()};
  const pid_t server = coredem::e2e::startProgram(kBin / "coredem-dem", args, dir / "server.log");
  ASSERT_GT(server, 0);
  const auto end = std::chrono::steady_clock::now() + 20s;
  while (!fs::exists(dir / "endpoint") && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(10ms);
  }
  std::string endpoint = readAll(dir / "endpoint");
  while (!endpoint.empty() && std::isspace(static_cast<unsigned char>(endpoint.back()))) {
    endpoint.pop_back();
  }
  ASSERT_FALSE(endpoint.empty()) << readAll(dir / "server.log");

  auto writeCase = [&](const std::string& name, const std::string& clientKey) {
    std::string text = readAll(kCases / "restart" / "case.yaml");
    text.replace(text.find("  end: 0.1"), 10, "  end: 0.01"); // 20 steps
    std::string demSection = "dem:\n  endpoint: " + endpoint +
                             "\n  server_key: " + (dir / "server" / "server.public").string() +
                             "\n";
    if (!clientKey.empty()) {
      demSection += "  client_key: " + clientKey + "\n";
    }
    text.replace(text.find("dem:\n"), 5, demSection);
    fs::create_directories(dir / name);
    std::ofstream(dir / name / "case.yaml") << text;
  };
  writeCase("alice", (dir / "alice" / "client.secret").string()); // the secret file
  writeCase("alice-dir", (dir / "alice").string());               // or its folder
  writeCase("mallory", (dir / "mallory").string());               // a key not on the list
  writeCase("anonymous", "");                                     // a throw-away pair

  for (const std::string name : {"alice", "alice-dir"}) {
    EXPECT_EQ(coredem::e2e::waitExit(
                  coredem::e2e::startProgram(kBin / "coredem",
                                             {"run", (dir / name).string(), "--out",
                                              (dir / ("run-" + name)).string(), "--no-plots"},
                                             dir / (name + ".log")),
                  60s),
              0)
        << readAll(dir / (name + ".log")) << readAll(dir / "server.log");
    EXPECT_TRUE(fs::exists(dir / ("run-" + name) / "checkpoints/00000020/manifest.json"));
  }
  // The CFD participant got a path, never the secret itself.
  const std::string cfdLog = readAll(dir / "run-alice" / "logs" / "cfd.log");
  EXPECT_EQ(cfdLog.find(readAll(dir / "alice" / "client.secret").substr(0, 40)), std::string::npos);

  // Refused at once (the case's dem.timeout_s is 20 s; the server answers the handshake), the
  // key named, exit 1.
  for (const std::string name : {"mallory", "anonymous"}) {
    EXPECT_EQ(
        coredem::e2e::waitExit(coredem::e2e::startProgram(kBin / "coredem",
                                                          {"run", (dir / name).string(), "--out",
                                                           (dir / ("run-" + name)).string()},
                                                          dir / (name + ".log")),
                               60s),
        1);
    const std::string log = readAll(dir / (name + ".log"));
    EXPECT_NE(log.find("refused this client's CURVE key"), std::string::npos) << log;
    EXPECT_NE(log.find("allow-list"), std::string::npos) << log;
  }
  EXPECT_NE(
      readAll(dir / "mallory.log").find(readAll(dir / "mallory" / "client.public").substr(0, 40)),
      std::string::npos);
  ::kill(server, SIGTERM);
  EXPECT_EQ(coredem::e2e::waitExit(server, 20s), 0) << readAll(dir / "server.log");
}
