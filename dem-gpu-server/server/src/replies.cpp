#include "replies.h"

#include "coupling_fields.h"

namespace coredem::server {

namespace v1 = coredem::v1;
namespace proto = coredem::protocol;

namespace {
/// Longest error text sent back to a peer (longer ones are cut, "...(N bytes)").
constexpr std::size_t kMaxReplyText = 4096;
} // namespace

void Replies::send(const proto::PeerId& peer, proto::Message m, std::uint64_t sequence,
                   std::int64_t step) {
  // The session id goes to the session's members only (docs/security.md): a stranger's reply
  // carries none, in the envelope or the text.
  m.setSessionId(_members.isMember(peer) ? _members.session() : std::string());
  m.setSequence(sequence);
  m.setStep(step);
  _server.reply(peer, std::move(m));
}

void Replies::refuse(const proto::Request& r, v1::ErrorCode code, const std::string& message) {
  const auto& env = r.message.envelope();
  const std::string& session = _members.session();
  _log->warn("session {}: refused {} from {}: {}: {}", session.empty() ? "-" : session,
             proto::messageTypeName(env.type()), _members.peerName(r.peer),
             proto::errorCodeName(code), safe(message, 400));
  // Our own text with escaped, capped peer strings; capped as a whole too.
  send(r.peer,
       proto::makeError(code,
                        message.size() > kMaxReplyText ? safe(message, kMaxReplyText) : message,
                        env.sequence(), env.type()),
       env.sequence(), env.step());
}

void Replies::reject(const proto::Request& r, v1::ErrorCode code, const std::string& reason) {
  const auto& env = r.message.envelope();
  _log->warn("rejected Hello from '{}' ({}): {}: {}", safe(env.sender()), hexPeer(r.peer),
             proto::errorCodeName(code), safe(reason, 400));
  auto m = proto::makeReject(code, reason);
  m.envelope().mutable_reject()->set_server_protocol_major(proto::kProtocolVersion.major);
  m.envelope().mutable_reject()->set_server_protocol_minor(proto::kProtocolVersion.minor);
  m.setSequence(env.sequence());
  _server.reply(r.peer, std::move(m));
}

void Replies::refuseAll(const std::vector<StepReply>& to, v1::ErrorCode code,
                        const std::string& text) {
  for (const StepReply& t : to) {
    refuse(*t.request, code, text);
  }
}

void Replies::sendSources(const std::vector<StepReply>& to, const proto::Message& gasMessage,
                          const dem::CellSources& s, const v1::Ledger& ledger, double dtCfd,
                          std::uint32_t nSub, const GridShape& grid) {
  namespace f = proto::fields;
  const auto& env = gasMessage.envelope();
  const std::uint64_t cells = grid.cells;
  const std::uint32_t species = grid.species;
  const auto n = static_cast<std::size_t>(cells);
  for (const StepReply& t : to) {
    const auto& req = t.request->message.envelope();
    const std::uint64_t rows = t.partial ? t.cells.size() : cells;
    auto src = proto::makeSources(env.step(), env.time(), dtCfd, cells, species, nSub);
    if (t.partial) {
      src.envelope().mutable_sources()->set_partial(true);
      src.envelope().mutable_sources()->set_touched_count(rows);
      src.addArray<std::int64_t>(f::kTouchedCells, t.cells, {rows});
    }
    std::vector<double> picked;
    auto add = [&](std::string_view name, const std::vector<double>& v) {
      std::span<const double> values(v);
      if (t.partial) {
        const std::size_t q = v.size() / n;
        picked.resize(t.cells.size() * q);
        for (std::size_t i = 0; i < t.cells.size(); ++i) {
          for (std::size_t c = 0; c < q; ++c) {
            picked[i * q + c] = v[static_cast<std::size_t>(t.cells[i]) * q + c];
          }
        }
        values = picked;
      }
      src.addArray<double>(name, values, f::shapeOf(name, rows, species));
    };
    for (const f::FieldSpec& spec : f::sourceFields()) { // the table's order
      add(spec.name, sourceValues(s, spec.name));
    }
    // v1.3: the radiation heat of the particles goes to the gas; an older peer never sees it
    // (the heat then stays with the particles' environment, as before 1.3). v1.5: the momentum of
    // the released mass; an older peer never sees it (the mass enters at the gas velocity).
    const int r = _members.rankOf(t.request->peer);
    const std::uint32_t minor = r >= 0 ? _members.rankMinor(static_cast<std::size_t>(r)) : 0;
    if (r >= 0 && minor >= proto::kMinorRadiation && s.qRad.size() == n) {
      add(f::kRadiationHeat, sourceValues(s, f::kRadiationHeat));
    }
    if (r >= 0 && minor >= proto::kMinorReleasedMomentum && s.momP.size() == 3 * n) {
      add(f::kReleasedMomentum, sourceValues(s, f::kReleasedMomentum));
    }
    *src.envelope().mutable_sources()->mutable_ledger() = ledger;
    send(t.request->peer, std::move(src), req.sequence(), env.step());
  }
}

} // namespace coredem::server
