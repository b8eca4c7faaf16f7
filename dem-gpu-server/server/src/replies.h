#pragma once
// The DEM server's replies: every message it sends goes through here, with the envelope's
// session id (for the session's members only, docs/security.md), sequence and step; refusals
// (Error, logged) and rejections of a Hello (Reject); the Sources of a step, whole-grid or per
// CFD rank.
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "coredem/common/log.h"
#include "coredem/dem/dem_system.h"
#include "coredem/protocol/protocol.h"
#include "membership.h"

namespace coredem::server {

/// One reply of a step: the request it answers and, for a partial GasFields, its cells.
struct StepReply {
  const protocol::Request* request = nullptr;
  std::span<const std::int64_t> cells; ///< partial: the rank's coupling cells
  bool partial = false;
};

/// The coupling grid of a configured session, as the replies shape their arrays.
struct GridShape {
  std::uint64_t cells = 0;
  std::uint32_t species = 0;
};

class Replies {
public:
  Replies(protocol::Server& server, const Membership& members, std::shared_ptr<spdlog::logger> log)
      : _server(server)
      , _members(members)
      , _log(std::move(log)) {}

  /// Sends `m` with the session id (members only), `sequence` and `step` in its envelope.
  void send(const protocol::PeerId& peer, protocol::Message m, std::uint64_t sequence,
            std::int64_t step);
  /// An Error answering `r` (logged as a warning); the text is capped.
  void refuse(const protocol::Request& r, v1::ErrorCode code, const std::string& message);
  void refuse(const protocol::Request& r, const Refusal& why) { refuse(r, why.code, why.text); }
  /// A Reject answering a Hello (never with a session id).
  void reject(const protocol::Request& r, v1::ErrorCode code, const std::string& reason);
  /// The same Error to every request of a step.
  void refuseAll(const std::vector<StepReply>& to, v1::ErrorCode code, const std::string& text);
  /// The Sources answering the GasFields `gasMessage` of a step granted with `dtCfd` and `nSub`:
  /// the whole grid, or each rank's cells (decomposed CFD); Q_rad only to peers of 1.3+.
  void sendSources(const std::vector<StepReply>& to, const protocol::Message& gasMessage,
                   const dem::CellSources& s, const v1::Ledger& ledger, double dtCfd,
                   std::uint32_t nSub, const GridShape& grid);

private:
  protocol::Server& _server;
  const Membership& _members;
  std::shared_ptr<spdlog::logger> _log;
};

} // namespace coredem::server
