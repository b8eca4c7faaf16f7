#pragma once
/// @file
/// The loopback (echo) service: a minimal, complete protocol server used by the tests, the
/// benchmark and `make run` (binary `coredem-loopback serve|exchange`, target
/// coredem::loopback). It plays the DEM server's role without any physics:
///
/// * Hello -> Welcome (same major, agreed minor = min) or Reject (VERSION; SESSION_BUSY when
///   another peer holds the session).
/// * Configure -> Configured (validateConfigure; cells from the Cartesian grid, 0 particles).
/// * GasFields (step = expected step, starting at Configure.start_step, +1 per accepted
///   GasFields) -> Sources for an empty particle bed: eps_g = 1 and K_sl, K_sl_Us, H, H_Tp,
///   R_species, Q_hom = 0, plus one extra array "checksum" [8] = the sum of every value of
///   each GasFields array in fields::gasFields() order (lets a client verify the transfer).
/// * StepGrant -> StepDone, CheckpointRequest -> CheckpointDone (no files),
///   Heartbeat -> Heartbeat, Shutdown -> Ack and serve() returns.
/// * Anything invalid -> Error{code, message}; the state is unchanged and serving goes on.
/// Sequence numbers of the session peer must increase; the session id of Welcome is required
/// in every later message.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include <coredem/protocol/transport.h>
#include <coredem/protocol/version.h>

namespace coredem::protocol {

class LoopbackService {
public:
  /// `version` is the protocol version the service claims (tests use other versions).
  explicit LoopbackService(TransportOptions options = {}, Version version = kProtocolVersion);
  ~LoopbackService();
  LoopbackService(const LoopbackService&) = delete;
  LoopbackService& operator=(const LoopbackService&) = delete;

  /// Binds the ROUTER socket; returns the bound endpoint.
  std::string bind(const std::string& endpoint);

  /// Handles at most one request, waiting up to `timeout`. Returns false once a Shutdown has
  /// been acknowledged.
  bool serveOne(std::chrono::milliseconds timeout);
  /// Serves until Shutdown, `stop` becomes true (checked every 100 ms), or `idleLimit` passes
  /// without any request (0 = no limit). Returns the number of requests handled.
  std::uint64_t serve(const std::atomic<bool>* stop = nullptr,
                      std::chrono::milliseconds idleLimit = std::chrono::milliseconds{0});

  /// Counters for tests.
  [[nodiscard]] std::uint64_t requestsHandled() const;
  [[nodiscard]] std::uint64_t errorsSent() const;

private:
  struct Impl;
  std::unique_ptr<Impl> _impl;
};

} // namespace coredem::protocol
