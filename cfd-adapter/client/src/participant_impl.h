// Participant::Impl, the state of a coupling client (participant.cpp: start, grants, control
// state, end; participant_exchange.cpp: the exchange of a step). Private to the library.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "coredem/client/participant.h"
#include "coredem/common/log.h"
#include "coredem/protocol/protocol.h"

namespace coredem::client {

namespace v1 = coredem::v1;
namespace proto = coredem::protocol;

namespace detail {

/// The software version sent when Options::softwareVersion is empty.
extern const std::string kLibraryVersion;
constexpr double kDefaultTimeoutS = 60.0;
/// |dt - granted dt| <= kDtTolerance * granted dt (the DEM sub-cycles exactly the granted dt).
constexpr double kDtTolerance = 1e-12;

/// `given` when not empty, else the environment variable `var` (empty when unset).
std::string fromEnv(const std::string& given, const char* var);

} // namespace detail

struct Participant::Impl {
  Options opt;
  State state = State::Created;
  std::chrono::milliseconds timeout{60000};
  std::string controlEp, demEp, session;
  std::unique_ptr<proto::Client> control, dem;
  std::shared_ptr<spdlog::logger> log = coredem::logger("client");

  Grid grid;
  std::int64_t startStep = 0;
  double startTime = 0.0;

  // The current grant.
  std::int64_t step = 0;
  double time = 0.0, dt = 0.0, dtDem = 0.0;
  int nSub = 0;
  std::string checkpointDir;
  bool outputRequested = false;
  std::string shutdownReason;

  Sources sources;
  ExchangeTimes times;
  int demMinor = 0; ///< the protocol minor agreed with D
  /// setHeatToParticles(): the Q_split values for the next exchange (sent once, then cleared)
  std::vector<double> heatToParticles;
  bool hasHeatToParticles = false;

  bool decomposed() const { return opt.rankCount > 1; }

  void require(std::initializer_list<State> allowed, const char* call, const char* hint) const {
    for (State s : allowed) {
      if (s == state) {
        return;
      }
    }
    throw StateError(
        fmt::format("Participant::{}() called in state {}: {}", call, stateName(state), hint));
  }

  proto::TransportOptions transport(bool forDem) const;

  /// Takes a grant or Shutdown reply of O.
  void takeGrantOrShutdown(const proto::Message& reply, std::int64_t expectedStep);

  proto::Message handshake(proto::Client& client, const std::string& peer, bool rank = false);

  void checkRank() const;

  /// Hello to D (with the rank of a decomposed run); a decomposed run needs protocol 1.2.
  void connectDem();

  void readEnvironment();

  void initialize();

  // ---- the exchange of a step (participant_exchange.cpp) --------------------------------
  /// exchange() of the whole grid (touched == nullptr) or of a rank's cells (exchangePartial).
  const Sources& exchange(std::int64_t s, double d, const std::vector<NamedField>& fields,
                          const std::vector<NamedBuffer>& into,
                          const std::vector<std::int64_t>* touched = nullptr,
                          ConstView fluidVolume = ConstView());
  /// "the DEM server at ... agreed protocol 1.m, this client speaks ..." (for errors).
  std::string versionsAgreed() const;
  /// Checks an exchange call: the granted step and dt; of a partial exchange, the cell list
  /// (strictly ascending coupling cells) and the cells' fluid volumes.
  void checkExchangeCall(std::int64_t s, double d, const std::vector<std::int64_t>* touched,
                         ConstView fluidVolume) const;
  /// The given gas fields by name: GasFields arrays, each given once.
  std::map<std::string, ConstView> givenGasFields(const std::vector<NamedField>& fields,
                                                  bool partial) const;
  /// The caller's buffers by Sources array name, each holding `cells` rows of its array.
  std::map<std::string, const NamedBuffer*> sourceBuffers(const std::vector<NamedBuffer>& into,
                                                          std::uint64_t cells) const;
  /// The GasFields message of the granted step (whole grid, or the touched cells).
  proto::Message gasFieldsMessage(const std::map<std::string, ConstView>& given,
                                  const std::vector<std::int64_t>* touched,
                                  ConstView fluidVolume) const;
  /// D's answer to the request with sequence `seq`, by `deadline`; replies to earlier, timed-out
  /// requests are skipped.
  proto::Message awaitReply(std::uint64_t seq, std::chrono::steady_clock::time_point deadline);
  /// Checks D's Sources: valid for the step, and of the cells that were sent.
  void checkSources(const proto::Message& reply, const std::vector<std::int64_t>* touched) const;
  /// Makes D's Sources the current sources: arrays with a buffer are copied into it (after
  /// every size was checked), the others are viewed in the kept message.
  void takeSources(proto::Message reply, const std::map<std::string, const NamedBuffer*>& dest);

  void advance(double courant, const Ledgers& ledgers, const std::vector<std::string>& files);

  // ---- decomposed runs: rank 0's control state for the other ranks ----------------------
  std::string controlState() const;

  void follow(const std::string& text);

  void finalize();
};

} // namespace coredem::client
