#pragma once
/// @file
/// The DEM server `coredem-dem` as a library (the executable is a thin main around it; tests
/// run it in-process too). It speaks protocol v1 on one ROUTER socket and plays D in
/// docs/session.md: one session at a time, Configure → particles, StepGrant + GasFields →
/// Sources + StepDone, checkpoints, heartbeats, Shutdown.
///
/// @code
///   coredem::server::ServerOptions o;
///   o.bind = "tcp://127.0.0.1:*";
///   coredem::server::DemServer server(o);
///   std::cout << server.endpoint();     // the bound endpoint, e.g. tcp://127.0.0.1:40125
///   server.run();                       // until stop(), or the session ends with exitAfterSession
/// @endcode
/// Any invalid message gets an Error reply (code + what to do) and changes nothing.

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

namespace coredem::server {

struct ServerOptions {
  std::string bind = "tcp://127.0.0.1:*";
  std::string backend = "cpu";        ///< cpu | cuda | auto
  int threads = 0;                    ///< OpenMP threads (0 = OpenMP default)
  double sessionTimeoutSeconds = 600; ///< a session whose peers are silent this long ends
  /// How long a GasFields may wait for the orchestrator's StepGrant of its step.
  double grantWaitSeconds = 60;
  std::string curveKeysDir; ///< DIR/server.public + DIR/server.secret (Z85)
  /// Allow-list of client public keys (one Z85 key per line, like ssh `authorized_keys`; needs
  /// curveKeysDir): only these clients complete the CURVE handshake. Empty: any client that
  /// knows the server's public key.
  std::string clientKeysFile;
  bool insecure = false;         ///< allow a non-loopback bind without CURVE
  bool exitAfterSession = false; ///< run() returns when the first session ends
  /// Admission control (docs/security.md): the memory budget the count limits of a Configure
  /// derive from (0: half of the physical memory), the largest message part any peer may send
  /// (ZMQ_MAXMSGSIZE; a larger one closes its connection) and the most sub-steps per grant.
  std::uint64_t maxMemoryBytes = 0;
  std::int64_t maxMessageBytes = std::int64_t{256} << 20;
  std::uint64_t maxSubSteps = 100000;
  /// Per-stage timers (docs/performance.md "Timers"): a report in the log every `timersEvery`
  /// CFD steps (0: only at the end) and at the end of each session, written as JSON to
  /// `timersFile` (empty: coredem-dem-timers.json in the working directory).
  bool timers = false;
  int timersEvery = 100;
  std::string timersFile;
};

/// Session life cycle (one at a time):
/// Idle --Hello(O)--> Connected --Configure--> Configured --StepGrant/GasFields...--> Shutdown →
/// Idle
enum class SessionState { Idle, Connected, Configured };

class DemServer {
public:
  /// Binds (UserError with what to do for a bad endpoint or a refused non-loopback bind).
  explicit DemServer(ServerOptions options);
  ~DemServer();
  DemServer(const DemServer&) = delete;
  DemServer& operator=(const DemServer&) = delete;

  /// The bound endpoint (actual port for tcp://...:*).
  std::string endpoint() const;
  SessionState sessionState() const;

  /// Serves until stop() is called or, with exitAfterSession, the first session ended.
  /// Returns the process exit code (0 = normal).
  int run();
  /// Handles at most one message (or housekeeping), waiting up to `wait`. Returns false once
  /// the server should stop.
  bool poll(std::chrono::milliseconds wait);
  /// Thread-safe; run() returns after the message being handled.
  void stop();

private:
  struct Impl;
  std::unique_ptr<Impl> _impl;
};

/// Writes a new CURVE key pair into DIR/server.public and DIR/server.secret (mode 0600).
void generateCurveKeys(const std::string& dir);
/// Writes a new client key pair into DIR/client.public and DIR/client.secret (mode 0600); the
/// public key goes into the server's --client-keys allow-list.
void generateClientKey(const std::string& dir);

} // namespace coredem::server
