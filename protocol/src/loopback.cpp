#include <random>
#include <thread>

#include <coredem/common/log.h>
#include <coredem/protocol/fields.h>
#include <coredem/protocol/loopback.h>
#include <coredem/protocol/validate.h>

namespace coredem::protocol {

namespace {
constexpr const char* kSoftware = "coredem-loopback 1.0";
}

struct LoopbackService::Impl {
  Impl(TransportOptions options, Version v)
      : server(std::move(options))
      , version(v) {}

  Server server;
  Version version;
  std::shared_ptr<spdlog::logger> log = logger("protocol.loopback");

  // session state
  std::optional<PeerId> sessionPeer;
  std::string sessionId;
  std::uint64_t lastSequence = 0;
  bool configured = false;
  std::uint64_t cells = 0;
  std::uint32_t species = 0;
  std::int64_t expectedStep = 0;
  std::uint32_t nSub = 1;

  bool shutdown = false;
  std::uint64_t handled = 0;
  std::uint64_t errors = 0;

  void sendError(const PeerId& peer, const Status& s, const Message& offending) {
    ++errors;
    log->warn("refused {}: {}", messageTypeName(offending.type()), printable(s.toString(), 400));
    server.reply(peer, makeError(s, offending.envelope().sequence(), offending.type()));
  }

  void handle(Request& req) {
    ++handled;
    Message& m = req.message;
    if (!req.status.ok()) {
      sendError(req.peer, req.status, m);
      return;
    }
    // Hello: the only message accepted without a session.
    if (m.type() == v1::MESSAGE_TYPE_HELLO) {
      Expectation e;
      e.types = {v1::MESSAGE_TYPE_HELLO};
      if (Status s = validate(m, e); !s.ok()) {
        sendError(req.peer, s, m);
        return;
      }
      handleHello(req);
      return;
    }
    if (!sessionPeer || *sessionPeer != req.peer) {
      Expectation e; // structural checks still give the most specific code
      if (Status s = validate(m, e); !s.ok()) {
        sendError(req.peer, s, m);
        return;
      }
      sendError(req.peer,
                Status::error(v1::ERROR_CODE_NOT_CONFIGURED,
                              "no session: send Hello first (and Configure before data)"),
                m);
      return;
    }
    Expectation e;
    e.sessionId = sessionId;
    e.sequenceAfter = lastSequence;
    if (configured) {
      e.cells = cells;
      e.species = species;
    }
    if (m.type() == v1::MESSAGE_TYPE_GAS_FIELDS) {
      e.step = expectedStep;
    }
    Status s = validate(m, e);
    if (s.ok() && !configured &&
        (m.type() == v1::MESSAGE_TYPE_STEP_GRANT ||
         m.type() == v1::MESSAGE_TYPE_CHECKPOINT_REQUEST)) {
      s = Status::error(v1::ERROR_CODE_NOT_CONFIGURED,
                        messageTypeName(m.type()) + " before Configure; send Configure first");
    }
    if (m.envelope().sequence() > lastSequence &&
        (s.ok() || s.code != v1::ERROR_CODE_UNKNOWN_SESSION)) {
      lastSequence = m.envelope().sequence(); // numbers only increase, even for refused ones
    }
    if (!s.ok()) {
      sendError(req.peer, s, m);
      return;
    }
    const auto seq = m.envelope().sequence();
    Message reply;
    switch (m.type()) {
    case v1::MESSAGE_TYPE_CONFIGURE: {
      const auto& c = m.envelope().configure();
      if (Status cs = validateConfigure(c); !cs.ok()) {
        sendError(req.peer, cs, m);
        return;
      }
      configured = true;
      cells = cellCount(c.coupling_mesh());
      species = static_cast<std::uint32_t>(c.species_size());
      expectedStep = c.start_step();
      nSub = c.sub_cycling().n_sub();
      reply = makeConfigured(cells, 0, species, nSub, c.sub_cycling().dt_dem());
      log->info("configured: {} cells, {} species, start step {}", cells, species, expectedStep);
      break;
    }
    case v1::MESSAGE_TYPE_GAS_FIELDS:
      reply = sources(m);
      ++expectedStep;
      break;
    case v1::MESSAGE_TYPE_STEP_GRANT: {
      v1::StepDone done;
      reply = makeStepDone(m.envelope().step(),
                           m.envelope().time() + m.envelope().step_grant().dt_cfd(), done);
      break;
    }
    case v1::MESSAGE_TYPE_CHECKPOINT_REQUEST:
      reply = makeCheckpointDone(m.envelope().step(), m.envelope().checkpoint_request().directory(),
                                 {});
      break;
    case v1::MESSAGE_TYPE_HEARTBEAT:
      reply = makeHeartbeat(configured ? "configured" : "connected");
      break;
    case v1::MESSAGE_TYPE_SHUTDOWN:
      reply = makeAck("shutting down");
      shutdown = true;
      break;
    default:
      sendError(req.peer,
                Status::error(v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                              "the loopback server does not accept " + messageTypeName(m.type()) +
                                  " messages"),
                m);
      return;
    }
    reply.setSequence(seq).setSessionId(sessionId);
    server.reply(req.peer, std::move(reply));
  }

  void handleHello(Request& req) {
    const auto& h = req.message.envelope().hello();
    const auto seq = req.message.envelope().sequence();
    if (sessionPeer && *sessionPeer != req.peer) {
      ++errors;
      Message r = makeReject(v1::ERROR_CODE_SESSION_BUSY,
                             "this server already serves another session; start another "
                             "server for a second session"); // never the id to a non-member
      r.setSequence(seq);
      server.reply(req.peer, std::move(r));
      return;
    }
    Negotiation n = negotiate(version, Version{h.protocol_major(), h.protocol_minor()});
    if (!n.accepted) {
      ++errors;
      Message r = makeReject(n.status.code, n.status.message);
      r.envelope().mutable_reject()->set_server_protocol_major(version.major);
      r.envelope().mutable_reject()->set_server_protocol_minor(version.minor);
      r.setSequence(seq);
      server.reply(req.peer, std::move(r));
      return;
    }
    // A (re-)Hello from the session peer starts a fresh session.
    std::random_device rd;
    sessionId = "loopback-" + std::to_string(rd()) + std::to_string(rd());
    sessionPeer = req.peer;
    lastSequence = seq;
    configured = false;
    Message w = makeWelcome(v1::ROLE_DEM, kSoftware, n.agreed.major, n.agreed.minor, sessionId);
    w.setSequence(seq);
    log->info("session {} opened for {} (protocol {})", sessionId, h.software_version(),
              n.agreed.toString());
    server.reply(req.peer, std::move(w));
  }

  Message sources(const Message& in) {
    const auto& env = in.envelope();
    Message out = makeSources(env.step(), env.time(), env.gas_fields().dt(), cells, species, nSub);
    std::vector<double> checksum;
    for (const auto& f : fields::gasFields()) {
      double sum = 0;
      for (double v : in.values<double>(f.name)) {
        sum += v;
      }
      checksum.push_back(sum);
    }
    // Empty particle bed: eps_g = 1, every source zero (docs/protocol.md, loopback server).
    for (const auto& f : fields::sourceFields()) {
      auto shape = fields::shapeOf(f.extent, cells, species);
      std::size_t n = cells * fields::componentsOf(f.extent, species);
      auto values =
          std::make_shared<std::vector<double>>(n, f.name == fields::kVoidFraction ? 1.0 : 0.0);
      out.addArrayShared<double>(f.name, values, std::span<const double>(*values),
                                 std::move(shape));
    }
    out.addArray<double>("checksum", checksum, {checksum.size()});
    return out;
  }
};

LoopbackService::LoopbackService(TransportOptions options, Version version)
    : _impl(std::make_unique<Impl>(std::move(options), version)) {}
LoopbackService::~LoopbackService() = default;

std::string LoopbackService::bind(const std::string& endpoint) {
  return _impl->server.bind(endpoint);
}

bool LoopbackService::serveOne(std::chrono::milliseconds timeout) {
  if (_impl->shutdown) {
    return false;
  }
  std::optional<Request> req;
  try {
    req = _impl->server.receive(timeout);
  } catch (const TransportError& e) {
    // A socket-level failure must not end the service: log it and go on serving.
    _impl->log->error("receive failed: {}", e.what());
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    return !_impl->shutdown;
  }
  if (req) {
    try {
      _impl->handle(*req);
    } catch (const std::exception& e) {
      // Never crash on a request: report it to the peer and go on.
      _impl->sendError(req->peer,
                       Status::error(v1::ERROR_CODE_INTERNAL,
                                     std::string("loopback server failed: ") + e.what()),
                       req->message);
    }
  }
  return !_impl->shutdown;
}

std::uint64_t LoopbackService::serve(const std::atomic<bool>* stop,
                                     std::chrono::milliseconds idleLimit) {
  using Clock = std::chrono::steady_clock;
  auto lastActivity = Clock::now();
  std::uint64_t before = _impl->handled;
  while (!_impl->shutdown && !(stop && stop->load())) {
    std::uint64_t n = _impl->handled;
    serveOne(std::chrono::milliseconds(100));
    if (_impl->handled != n) {
      lastActivity = Clock::now();
    } else if (idleLimit.count() > 0 && Clock::now() - lastActivity > idleLimit) {
      _impl->log->warn("no request for {} ms: stopping", idleLimit.count());
      break;
    }
  }
  return _impl->handled - before;
}

std::uint64_t LoopbackService::requestsHandled() const {
  return _impl->handled;
}
std::uint64_t LoopbackService::errorsSent() const {
  return _impl->errors;
}

} // namespace coredem::protocol
