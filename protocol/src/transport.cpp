// ZeroMQ transport: Server and Client. ZeroMQ stays private: only this file and
// transport_curve.cpp (CURVE keys, the ZAP handler) include zmq.hpp.
#include <atomic>
#include <cstring>
#include <map>
#include <mutex>
#include <utility>

#include <zmq.hpp>

#include <coredem/common/log.h>
#include <coredem/protocol/transport.h>

#include "message_impl.h"
#include "transport_internal.h"

namespace coredem::protocol {

namespace detail {

std::shared_ptr<spdlog::logger> transportLog() {
  static auto log = logger("protocol.transport");
  return log;
}

[[noreturn]] void rethrowZmq(const zmq::error_t& e, const std::string& what) {
  throw TransportError(what + ": ZeroMQ error " + std::to_string(e.num()) + " (" + e.what() + ")");
}

/// One ZeroMQ context (one I/O thread) per process, shared by every Server and Client and
/// destroyed with the last of them. Measured: a client and a server in one process move data
/// about twice as fast through one shared I/O thread as through two contexts.
std::shared_ptr<zmq::context_t> sharedContext() {
  static std::mutex mutex;
  static std::weak_ptr<zmq::context_t> weak;
  std::lock_guard lock(mutex);
  auto context = weak.lock();
  if (!context) {
    context = std::make_shared<zmq::context_t>(1);
    weak = context;
  }
  return context;
}

} // namespace detail

namespace {

using Clock = std::chrono::steady_clock;
using detail::rethrowZmq;
using detail::setKey;
using detail::sharedContext;
using detail::transportLog;
using detail::ZapHandler;

void setCommonOptions(zmq::socket_t& socket, const TransportOptions& o) {
  socket.set(zmq::sockopt::linger, static_cast<int>(o.linger.count()));
  socket.set(zmq::sockopt::heartbeat_ivl, static_cast<int>(o.heartbeatInterval.count()));
  socket.set(zmq::sockopt::heartbeat_timeout, static_cast<int>(o.heartbeatTimeout.count()));
  socket.set(zmq::sockopt::heartbeat_ttl, static_cast<int>(o.heartbeatTimeout.count()));
  // A send never blocks forever: after 10 s it fails and is reported.
  socket.set(zmq::sockopt::sndtimeo, 10000);
  // A frame larger than this drops the connection before it is allocated.
  if (o.maxMessageBytes > 0) {
    socket.set(zmq::sockopt::maxmsgsize, o.maxMessageBytes);
  }
}

void freeShared(void* /*data*/, void* hint) {
  delete static_cast<std::shared_ptr<const void>*>(hint);
}

/// Sends envelope + arrays, arrays without copying (ZeroMQ holds a reference to the owner).
void sendMessage(zmq::socket_t& socket, const PeerId* peer, const Message& message,
                 const std::string& what) {
  const auto& impl = MessageAccess::impl(message);
  std::string env = serializeEnvelope(impl.envelope);
  try {
    if (peer) {
      socket.send(zmq::buffer(*peer), zmq::send_flags::sndmore);
    }
    auto more = impl.arrays.empty() ? zmq::send_flags::none : zmq::send_flags::sndmore;
    if (!socket.send(zmq::buffer(env), more)) {
      throw TransportError(what + ": send timed out (the peer does not read)");
    }
    for (std::size_t i = 0; i < impl.arrays.size(); ++i) {
      const Buffer& b = impl.arrays[i];
      auto flags = i + 1 < impl.arrays.size() ? zmq::send_flags::sndmore : zmq::send_flags::none;
      zmq::message_t frame;
      if (b.size > 0 && b.owner) {
        auto* hint = new std::shared_ptr<const void>(b.owner);
        frame = zmq::message_t(const_cast<std::byte*>(b.data), b.size, &freeShared, hint);
      } else if (b.size > 0) {
        frame = zmq::message_t(b.data, b.size); // caller-owned memory: copy
      }
      if (!socket.send(std::move(frame), flags)) {
        throw TransportError(what + ": send timed out (the peer does not read)");
      }
    }
  } catch (const zmq::error_t& e) {
    rethrowZmq(e, what);
  }
}

void sendRaw(zmq::socket_t& socket, const PeerId* peer, const Frames& frames,
             const std::string& what) {
  try {
    if (peer) {
      socket.send(zmq::buffer(*peer),
                  frames.empty() ? zmq::send_flags::none : zmq::send_flags::sndmore);
    }
    for (std::size_t i = 0; i < frames.size(); ++i) {
      auto flags = i + 1 < frames.size() ? zmq::send_flags::sndmore : zmq::send_flags::none;
      if (!socket.send(zmq::buffer(frames[i]), flags)) {
        throw TransportError(what + ": send timed out");
      }
    }
  } catch (const zmq::error_t& e) {
    rethrowZmq(e, what);
  }
}

/// Waits until the socket is readable or the deadline passes.
bool waitReadable(zmq::socket_t& socket, Clock::time_point deadline) {
  for (;;) {
    auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() < 0) {
      left = std::chrono::milliseconds(0);
    }
    zmq::pollitem_t item{socket.handle(), 0, ZMQ_POLLIN, 0};
    try {
      int n = zmq::poll(&item, 1, left);
      if (n > 0) {
        return true;
      }
    } catch (const zmq::error_t& e) {
      if (e.num() != EINTR) {
        rethrowZmq(e, "poll");
      }
    }
    if (Clock::now() >= deadline) {
      return false;
    }
  }
}

/// What receiveFrames dropped: a message over the limits keeps its first frames (routing id,
/// envelope) so that it can be answered, the rest is read and released at once.
struct Oversize {
  std::size_t frames = 0;
  std::uint64_t bytes = 0;
  bool exceeded = false;
};

/// Receives all frames of one multipart message (after poll said readable). With limits
/// (maxBytes > 0), frames beyond `keep` are released as soon as the message's frame count or
/// total size exceeds them.
std::vector<zmq::message_t> receiveFrames(zmq::socket_t& socket, const std::string& what,
                                          std::int64_t maxBytes = 0, std::size_t keep = 1,
                                          Oversize* over = nullptr, int* srcFd = nullptr,
                                          std::string* userId = nullptr) {
  std::vector<zmq::message_t> frames;
  Oversize o;
  try {
    for (;;) {
      zmq::message_t frame;
      if (!socket.recv(frame, zmq::recv_flags::dontwait)) {
        break; // parts of a multipart message arrive together; nothing more
      }
      bool more = frame.more();
      // The connection's fd (ZMQ_SRCFD). libzmq 4.3 leaves it off a ROUTER's routing-id frame
      // when poll() prefetched the message, so the first frame that has it is used.
      if (srcFd != nullptr && *srcFd < 0 && o.frames < 2) {
        *srcFd = zmq_msg_get(frame.handle(), ZMQ_SRCFD);
        // The ZAP handler's user id: the client's authenticated key (an allow-list only).
        const char* user = zmq_msg_gets(frame.handle(), "User-Id");
        if (userId != nullptr && user != nullptr) {
          *userId = user;
        }
      }
      ++o.frames;
      o.bytes += frame.size();
      if (maxBytes > 0 && (o.frames > kMaxFramesPerMessage + keep + 1 ||
                           o.bytes > static_cast<std::uint64_t>(maxBytes) + 4096)) {
        o.exceeded = true;
      }
      if (!o.exceeded || frames.size() < keep + 1) {
        frames.push_back(std::move(frame));
      }
      if (!more) {
        break;
      }
    }
  } catch (const zmq::error_t& e) {
    rethrowZmq(e, what);
  }
  if (o.exceeded) {
    frames.resize(std::min(frames.size(), keep + 1)); // routing id(s) + envelope
  }
  if (over != nullptr) {
    *over = o;
  }
  return frames;
}

/// Copies each array for which the BufferProvider returns a buffer into it and releases the
/// ZeroMQ frame; the message's views then point into the caller's buffers.
void applyBufferProvider(Message& message, const ReceiveOptions& options) {
  if (!options.buffers) {
    return;
  }
  auto& impl = MessageAccess::impl(message);
  for (std::size_t i = 0; i < impl.arrays.size(); ++i) {
    const auto& d = impl.envelope.arrays(static_cast<int>(i));
    std::span<std::byte> dst = options.buffers(d);
    if (dst.empty()) {
      continue;
    }
    Buffer& b = impl.arrays[i];
    COREDEM_CHECK(dst.size() >= b.size,
                  "BufferProvider returned {} bytes for array '{}' of {} bytes", dst.size(),
                  d.name(), b.size);
    if (b.size) {
      std::memcpy(dst.data(), b.data, b.size);
    }
    b = Buffer{nullptr, dst.data(), b.size};
  }
}

/// Decodes received frames [first, end) into a Message; applies the BufferProvider.
Status decodeFrames(std::vector<zmq::message_t>& frames, std::size_t first, Message& out,
                    const ReceiveOptions& options) {
  if (frames.size() <= first) {
    return decodeInto(out, nullptr, 0, {});
  }
  auto keepEnv = std::make_shared<zmq::message_t>(std::move(frames[first]));
  std::vector<Buffer> arrays;
  for (std::size_t i = first + 1; i < frames.size(); ++i) {
    auto keep = std::make_shared<zmq::message_t>(std::move(frames[i]));
    Buffer b{nullptr, static_cast<const std::byte*>(keep->data()), keep->size()};
    b.owner = std::move(keep);
    arrays.push_back(std::move(b));
  }
  Status s = decodeInto(out, static_cast<const std::byte*>(keepEnv->data()), keepEnv->size(),
                        std::move(arrays));
  if (s.ok()) {
    applyBufferProvider(out, options);
  }
  return s;
}

std::string describe(const Message& m) {
  const auto& env = m.envelope();
  return messageTypeName(env.type()) + " (sequence " + std::to_string(env.sequence()) + ", step " +
         std::to_string(env.step()) + ")";
}

} // namespace

// ---- Server ----------------------------------------------------------------------------

struct Server::Impl {
  TransportOptions options;
  std::shared_ptr<zmq::context_t> context = sharedContext(); // outlives the socket
  zmq::socket_t socket{*context, zmq::socket_type::router};
  /// Connection events of `socket` (ZMQ_EVENT_DISCONNECTED carries the connection's fd).
  zmq::socket_t monitor{*context, zmq::socket_type::pair};
  /// With an allow-list of client keys: the ZAP handler and this socket's domain in it.
  std::shared_ptr<ZapHandler> zap;
  std::string zapDomain;
  /// The connection (fd, and how many connections that fd had carried) each known peer's last
  /// message came on. The generation keeps a reused fd's new connection apart from the old.
  std::map<PeerId, std::pair<int, std::uint64_t>> fdOf;
  std::map<int, std::uint64_t> generation;              ///< ZMQ_EVENT_ACCEPTED count per fd
  static constexpr std::size_t kMaxDisconnected = 4096; ///< oldest dropped beyond this
  std::vector<PeerId> disconnected;                     ///< since the last takeDisconnected()
  std::string endpoint;
  std::shared_ptr<spdlog::logger> log = transportLog();

  void startMonitor() {
    static std::atomic<std::uint64_t> counter{0};
    const std::string address = "inproc://coredem-server-monitor-" + std::to_string(++counter);
    if (zmq_socket_monitor(socket.handle(), address.c_str(),
                           ZMQ_EVENT_ACCEPTED | ZMQ_EVENT_DISCONNECTED) != 0) {
      throw TransportError(std::string("starting the socket monitor failed: ") +
                           zmq_strerror(zmq_errno()));
    }
    monitor.connect(address);
  }

  /// Reads the pending monitor events; a closed connection's peers move to `disconnected`.
  void drainMonitor() {
    try {
      for (;;) {
        zmq::message_t event;
        if (!monitor.recv(event, zmq::recv_flags::dontwait)) {
          return;
        }
        const bool more = event.more();
        std::uint16_t id = 0;
        std::uint32_t value = 0;
        if (event.size() >= 6) {
          std::memcpy(&id, event.data(), 2);
          std::memcpy(&value, static_cast<const char*>(event.data()) + 2, 4);
        }
        if (more) {
          zmq::message_t address; // second frame: the endpoint
          (void)monitor.recv(address, zmq::recv_flags::dontwait);
        }
        const int fd = static_cast<int>(value);
        if (id == ZMQ_EVENT_ACCEPTED) {
          ++generation[fd];
          continue;
        }
        if (id != ZMQ_EVENT_DISCONNECTED) {
          continue;
        }
        for (auto it = fdOf.begin(); it != fdOf.end();) {
          if (it->second == std::make_pair(fd, generation[fd])) {
            if (disconnected.size() >= kMaxDisconnected) { // a server that never asks
              disconnected.erase(disconnected.begin());
            }
            disconnected.push_back(it->first);
            it = fdOf.erase(it);
          } else {
            ++it;
          }
        }
      }
    } catch (const zmq::error_t& e) {
      log->warn("socket monitor of {}: ZeroMQ error {} ({})", endpoint, e.num(), e.what());
    }
  }
};

Server::Server(TransportOptions options) {
  try {
    _impl = std::make_unique<Impl>();
    _impl->options = std::move(options);
    setCommonOptions(_impl->socket, _impl->options);
    _impl->socket.set(zmq::sockopt::router_mandatory, 1);
    _impl->startMonitor();
    if (_impl->options.curve.serverConfigured()) {
      int one = 1;
      zmq_setsockopt(_impl->socket.handle(), ZMQ_CURVE_SERVER, &one, sizeof(one));
      setKey(_impl->socket, ZMQ_CURVE_SECRETKEY, _impl->options.curve.serverSecretKey,
             "server secret key");
      if (!_impl->options.curve.allowedClientKeys.empty()) {
        _impl->zap = ZapHandler::instance();
        _impl->zapDomain = _impl->zap->addDomain(_impl->options.curve.allowedClientKeys);
        _impl->socket.set(zmq::sockopt::zap_domain, _impl->zapDomain);
      }
    }
  } catch (const zmq::error_t& e) {
    rethrowZmq(e, "creating the server socket");
  }
}

Server::~Server() {
  if (_impl && _impl->zap) {
    _impl->zap->removeDomain(_impl->zapDomain);
  }
}
Server::Server(Server&&) noexcept = default;
Server& Server::operator=(Server&&) noexcept = default;

std::string Server::bind(const std::string& endpoint) {
  if (!isLoopbackEndpoint(endpoint) && !_impl->options.curve.serverConfigured() &&
      !_impl->options.allowInsecure) {
    throw ProtocolError(
        v1::ERROR_CODE_SECURITY,
        "refusing to bind " + endpoint +
            ": a non-loopback endpoint requires CURVE keys (docs/architecture.md). Bind "
            "tcp://127.0.0.1:PORT or ipc://PATH, or set "
            "TransportOptions::curve (serverSecretKey/serverPublicKey)");
  }
  try {
    _impl->socket.bind(endpoint);
    _impl->endpoint = _impl->socket.get(zmq::sockopt::last_endpoint);
  } catch (const zmq::error_t& e) {
    rethrowZmq(e, "binding " + endpoint +
                      " (is the address valid and free? use tcp://127.0.0.1:* for any port)");
  }
  _impl->log->debug("server bound to {}", _impl->endpoint);
  return _impl->endpoint;
}

std::string Server::endpoint() const {
  return _impl->endpoint;
}

std::optional<Request> Server::receive(std::chrono::milliseconds timeout,
                                       const ReceiveOptions& options) {
  auto deadline = Clock::now() + timeout;
  if (!waitReadable(_impl->socket, deadline)) {
    return std::nullopt;
  }
  _impl->drainMonitor(); // closed connections first: their routing ids may be reused next
  Oversize over;
  int fd = -1;
  std::string userId;
  auto frames = receiveFrames(_impl->socket, "receiving on " + _impl->endpoint,
                              _impl->options.maxMessageBytes, 1, &over, &fd, &userId);
  if (frames.empty()) {
    return std::nullopt;
  }
  Request request;
  request.peer = frames[0].to_string();
  if (_impl->zap) {
    request.clientKey = userId;
  }
  if (fd >= 0) { // the monitor was drained first: generation[fd] is this connection's
    _impl->fdOf[request.peer] = {fd, _impl->generation[fd]};
  }
  if (over.exceeded) {
    frames.resize(std::min<std::size_t>(frames.size(), 2));
    (void)decodeFrames(frames, 1, request.message, {}); // the envelope, for sequence and type
    request.status = Status::error(
        v1::ERROR_CODE_BYTE_LENGTH,
        "message of " + std::to_string(over.frames) + " frames and " + std::to_string(over.bytes) +
            " bytes exceeds the limits of " + std::to_string(kMaxFramesPerMessage) +
            " arrays and " + std::to_string(_impl->options.maxMessageBytes) +
            " bytes (coredem-dem --max-message-mb); send smaller fields or raise the limit");
    _impl->log->warn("refused an oversized message on {}: {}", _impl->endpoint,
                     request.status.message);
    return request;
  }
  request.status = decodeFrames(frames, 1, request.message, options);
  if (!request.status.ok()) {
    _impl->log->debug("undecodable message on {}: {}", _impl->endpoint, request.status.toString());
  }
  return request;
}

void Server::reply(const PeerId& peer, Message message) {
  if (message.envelope().sender().empty() && !_impl->options.sender.empty()) {
    message.envelope().set_sender(_impl->options.sender);
  }
  try {
    sendMessage(_impl->socket, &peer, message, "replying " + describe(message));
  } catch (const TransportError& e) {
    // EHOSTUNREACH: the peer has gone; its reply is dropped (it will time out and report).
    _impl->log->warn("reply dropped: {}", e.what());
  }
}

std::vector<PeerId> Server::takeDisconnected() {
  _impl->drainMonitor();
  return std::exchange(_impl->disconnected, {});
}

void Server::replyFrames(const PeerId& peer, const Frames& frames) {
  sendRaw(_impl->socket, &peer, frames, "replying raw frames");
}

// ---- Client ----------------------------------------------------------------------------

struct Client::Impl {
  TransportOptions options;
  std::shared_ptr<zmq::context_t> context = sharedContext(); // outlives the socket
  zmq::socket_t socket{*context, zmq::socket_type::dealer};
  /// With CURVE: handshake failures of `socket` (a server whose allow-list lacks this
  /// client's key answers the handshake with an ERROR: ZMQ_EVENT_HANDSHAKE_FAILED_AUTH).
  std::optional<zmq::socket_t> monitor;
  std::string endpoint;
  std::uint64_t nextSequence = 1;
  std::shared_ptr<spdlog::logger> log = transportLog();

  void startMonitor() {
    static std::atomic<std::uint64_t> counter{0};
    const std::string address = "inproc://coredem-client-monitor-" + std::to_string(++counter);
    if (zmq_socket_monitor(socket.handle(), address.c_str(), ZMQ_EVENT_HANDSHAKE_FAILED_AUTH) !=
        0) {
      throw TransportError(std::string("starting the socket monitor failed: ") +
                           zmq_strerror(zmq_errno()));
    }
    monitor.emplace(*context, zmq::socket_type::pair);
    monitor->connect(address);
  }

  /// Throws ProtocolError(SECURITY) when the server refused this client's key.
  void checkHandshake() {
    if (!monitor) {
      return;
    }
    for (;;) {
      zmq::message_t event;
      if (!monitor->recv(event, zmq::recv_flags::dontwait)) {
        return;
      }
      std::uint16_t id = 0;
      std::uint32_t value = 0;
      if (event.size() >= 6) {
        std::memcpy(&id, event.data(), 2);
        std::memcpy(&value, static_cast<const char*>(event.data()) + 2, 4);
      }
      if (event.more()) {
        zmq::message_t address;
        (void)monitor->recv(address, zmq::recv_flags::dontwait);
      }
      if (id == ZMQ_EVENT_HANDSHAKE_FAILED_AUTH) {
        throw ProtocolError(
            v1::ERROR_CODE_SECURITY,
            "the server at " + endpoint + " refused this client's CURVE key " +
                options.curve.clientPublicKey + " (ZAP status " + std::to_string(value) +
                "): the key is not on its allow-list (coredem-dem --client-keys FILE); add the "
                "line of client.public to that file, or give the client key that is listed");
      }
    }
  }

  /// Waits until `socket` is readable (true) or the deadline passes (false); with CURVE,
  /// throws as soon as the server refuses the handshake.
  bool waitReadable(Clock::time_point deadline) {
    if (!monitor) {
      return coredem::protocol::waitReadable(socket, deadline);
    }
    for (;;) {
      checkHandshake();
      auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
      if (left.count() < 0) {
        left = std::chrono::milliseconds(0);
      }
      zmq::pollitem_t items[2] = {{socket.handle(), 0, ZMQ_POLLIN, 0},
                                  {monitor->handle(), 0, ZMQ_POLLIN, 0}};
      try {
        zmq::poll(items, 2, left);
        if ((items[0].revents & ZMQ_POLLIN) != 0) {
          return true;
        }
      } catch (const zmq::error_t& e) {
        if (e.num() != EINTR) {
          rethrowZmq(e, "poll");
        }
      }
      if ((items[1].revents & ZMQ_POLLIN) == 0 && Clock::now() >= deadline) {
        checkHandshake();
        return false;
      }
    }
  }
};

Client::Client(TransportOptions options) {
  try {
    _impl = std::make_unique<Impl>();
    _impl->options = std::move(options);
    setCommonOptions(_impl->socket, _impl->options);
    if (!_impl->options.routingId.empty()) {
      _impl->socket.set(zmq::sockopt::routing_id, _impl->options.routingId);
    }
    if (_impl->options.curve.clientConfigured()) {
      setKey(_impl->socket, ZMQ_CURVE_SERVERKEY, _impl->options.curve.serverPublicKey,
             "server public key");
      setKey(_impl->socket, ZMQ_CURVE_PUBLICKEY, _impl->options.curve.clientPublicKey,
             "client public key");
      setKey(_impl->socket, ZMQ_CURVE_SECRETKEY, _impl->options.curve.clientSecretKey,
             "client secret key");
      _impl->startMonitor();
    }
  } catch (const zmq::error_t& e) {
    rethrowZmq(e, "creating the client socket");
  }
}

Client::~Client() = default;
Client::Client(Client&&) noexcept = default;
Client& Client::operator=(Client&&) noexcept = default;

void Client::connect(const std::string& endpoint) {
  try {
    _impl->socket.connect(endpoint);
  } catch (const zmq::error_t& e) {
    rethrowZmq(e, "connecting to " + endpoint);
  }
  _impl->endpoint = endpoint;
}

std::string Client::endpoint() const {
  return _impl->endpoint;
}

std::uint64_t Client::nextSequence() const {
  return _impl->nextSequence;
}

std::uint64_t Client::send(Message message) {
  auto& env = message.envelope();
  if (env.sequence() == 0) {
    env.set_sequence(_impl->nextSequence);
  }
  if (env.sequence() >= _impl->nextSequence) {
    _impl->nextSequence = env.sequence() + 1;
  }
  if (env.sender().empty() && !_impl->options.sender.empty()) {
    env.set_sender(_impl->options.sender);
  }
  sendMessage(_impl->socket, nullptr, message,
              "sending " + describe(message) + " to " + _impl->endpoint);
  return env.sequence();
}

void Client::sendFrames(const Frames& frames) {
  sendRaw(_impl->socket, nullptr, frames, "sending raw frames to " + _impl->endpoint);
}

std::optional<Message> Client::receive(std::chrono::milliseconds timeout,
                                       const ReceiveOptions& options, Status* status) {
  auto deadline = Clock::now() + timeout;
  if (!_impl->waitReadable(deadline)) {
    return std::nullopt;
  }
  auto frames = receiveFrames(_impl->socket, "receiving from " + _impl->endpoint);
  Message m;
  Status s = decodeFrames(frames, 0, m, options);
  if (status) {
    *status = s;
  } else if (!s.ok()) {
    throw ProtocolError(s.code, "undecodable reply from " + _impl->endpoint + ": " + s.message);
  }
  return m;
}

Message Client::request(Message message, std::chrono::milliseconds timeout,
                        const ReceiveOptions& options) {
  const std::string what = describe(message);
  const auto type = message.type();
  const auto step = message.envelope().step();
  auto deadline = Clock::now() + timeout;
  std::uint64_t seq = send(std::move(message));
  for (;;) {
    auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    std::optional<Message> reply;
    if (left.count() > 0) {
      reply = receive(left, ReceiveOptions{}); // caller buffers only for the matching reply
    }
    if (!reply) {
      throw TimeoutError(_impl->endpoint, "reply to " + what,
                         "no reply from " + _impl->endpoint + " within " +
                             std::to_string(timeout.count()) + " ms while awaiting the reply to " +
                             messageTypeName(type) + " (sequence " + std::to_string(seq) +
                             ", step " + std::to_string(step) +
                             "); is the server running, reachable and not stalled?");
    }
    const auto& env = reply->envelope();
    if (env.sequence() == seq || (env.sequence() == 0 && reply->type() == v1::MESSAGE_TYPE_ERROR)) {
      applyBufferProvider(*reply, options);
      return std::move(*reply);
    }
    _impl->log->debug("discarding stale reply {} from {} (awaiting sequence {})", describe(*reply),
                      _impl->endpoint, seq);
  }
}

} // namespace coredem::protocol
