// coredem-dem: the DEM server (docs/client.md "coredem-dem: command line").
#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <CLI/CLI.hpp>
#include <unistd.h>

#include "admission.h"
#include "coredem/common/check.h"
#include "coredem/common/files.h"
#include "coredem/common/log.h"
#include "coredem/server/dem_server.h"

namespace {

std::atomic<coredem::server::DemServer*> gServer{nullptr};
std::atomic<int> gSignals{0};

/// SIGINT/SIGTERM: the first ends the session within a sub-step (a step in progress is
/// interrupted, both members are answered) and the server exits; a second one exits at once
/// with 128 + signal.
extern "C" void onSignal(int sig) {
  if (gSignals.fetch_add(1) >= 1) {
    static const char kMsg[] = "coredem-dem: second signal: exiting now\n";
    (void)!::write(2, kMsg, sizeof kMsg - 1);
    ::_exit(128 + sig);
  }
  if (auto* s = gServer.load()) {
    s->stop();
  }
}

void writeEndpointFile(const std::string& path, const std::string& endpoint) {
  coredem::writeFileAtomic(path, endpoint + "\n");
}

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"coredem-dem: the CoReDEM DEM server (protocol v1, one session at a time)"};
  coredem::server::ServerOptions o;
  std::string endpointFile, generateKeys;
  app.add_option("--bind", o.bind,
                 "endpoint to bind, e.g. tcp://127.0.0.1:* or ipc:///tmp/dem.sock")
      ->capture_default_str();
  app.add_option("--backend", o.backend, "cpu | cuda | auto")
      ->check(CLI::IsMember({"cpu", "cuda", "auto"}))
      ->capture_default_str();
  app.add_option("--threads", o.threads, "OpenMP threads of the cpu backend (0 = all)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--grant-wait-s", o.grantWaitSeconds,
                 "longest wait for a step's StepGrant after its GasFields, and for the other CFD "
                 "ranks' GasFields after the first rank's (a decomposed CFD participant)")
      ->check(CLI::PositiveNumber);
  app.add_option("--timeout-s", o.sessionTimeoutSeconds,
                 "end a session whose peers are silent this long (s)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option(
      "--curve-keys", o.curveKeysDir,
      "directory with server.public and server.secret (CURVE; needed for non-loopback binds)");
  app.add_option("--client-keys", o.clientKeysFile,
                 "allow-list of client public keys (one Z85 key per line, '#' comments; with "
                 "--curve-keys): only these clients may connect");
  std::string generateClientKeyDir;
  app.add_option("--generate-client-key", generateClientKeyDir,
                 "write a new client key pair into DIR/client.{public,secret} and exit");
  app.add_flag("--insecure", o.insecure,
               "allow a non-loopback bind without CURVE (trusted networks only)");
  app.add_flag(
      "--exit-after-session", o.exitAfterSession,
      "exit when the first session ends (set by the orchestrator that started this server)");
  std::string maxMemory;
  app.add_option("--max-memory", maxMemory,
                 "memory budget the count limits of a Configure derive from, e.g. 8G or 512M "
                 "(default: half of the physical memory); a Configure estimated above it is "
                 "refused before anything is allocated");
  double maxMessageMb = static_cast<double>(o.maxMessageBytes) / (1024.0 * 1024.0);
  app.add_option("--max-message-mb", maxMessageMb,
                 "largest message part (frame) a peer may send, MiB; a larger one closes its "
                 "connection (0: no limit)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--max-sub-steps", o.maxSubSteps,
                 "most DEM sub-steps per CFD step (StepGrant n_sub) the server accepts")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--endpoint-file", endpointFile, "write the bound endpoint into this file");
  app.add_flag("--timers", o.timers,
               "per-stage timers (DEM stages and the exchange): a log line every --timers-every "
               "steps, a table at the end of each session and a JSON file (--timers-file)");
  app.add_option("--timers-every", o.timersEvery,
                 "with --timers: log line every N CFD steps (0: only at the end)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option(
      "--timers-file", o.timersFile,
      "with --timers: JSON report path (default: dem-timers.json next to --endpoint-file, "
      "else coredem-dem-timers.json in the working directory)");
  app.add_option("--generate-curve-keys", generateKeys,
                 "write a new CURVE key pair into DIR/server.{public,secret} and exit");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  auto log = coredem::logger("dem.server");
  if (o.timers && o.timersFile.empty()) {
    o.timersFile =
        endpointFile.empty()
            ? std::string("coredem-dem-timers.json")
            : (std::filesystem::path(endpointFile).parent_path() / "dem-timers.json").string();
  }
  try {
    o.maxMessageBytes = static_cast<std::int64_t>(maxMessageMb * 1024.0 * 1024.0);
    if (!maxMemory.empty()) {
      try {
        o.maxMemoryBytes = coredem::server::parseBytes(maxMemory);
      } catch (const coredem::UserError& e) {
        log->error("--max-memory: {}", e.what());
        return 2;
      }
    }
    if (!generateClientKeyDir.empty()) {
      coredem::server::generateClientKey(generateClientKeyDir);
      std::cout << "client key pair written to " << generateClientKeyDir
                << "/client.{public,secret}; add client.public to the server's --client-keys "
                   "file\n";
      return 0;
    }
    if (!generateKeys.empty()) {
      coredem::server::generateCurveKeys(generateKeys);
      std::cout << "CURVE key pair written to " << generateKeys << "/server.{public,secret}\n";
      return 0;
    }
    std::unique_ptr<coredem::server::DemServer> server;
    try {
      server = std::make_unique<coredem::server::DemServer>(o);
    } catch (const coredem::UserError& e) {
      log->error("{}", e.what());
      return 2;
    }
    std::cout << "COREDEM_DEM_ENDPOINT=" << server->endpoint() << std::endl;
    if (!endpointFile.empty()) {
      writeEndpointFile(endpointFile, server->endpoint());
    }
    gServer.store(server.get());
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    const int rc = server->run();
    gServer.store(nullptr);
    return rc;
  } catch (const std::exception& e) {
    log->error("{}", e.what());
    return 1;
  }
}
