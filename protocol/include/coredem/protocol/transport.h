#pragma once
/// @file
/// ZeroMQ transport (ROUTER server / DEALER client). ZeroMQ itself stays private (pimpl).
///
/// Server side (e.g. the DEM server):
/// @code
///   using namespace coredem::protocol;
///   Server server;
///   std::string ep = server.bind("tcp://127.0.0.1:*");   // -> "tcp://127.0.0.1:41234"
///   while (running) {
///     std::optional<Request> req = server.receive(std::chrono::milliseconds(200));
///     if (!req) continue;                                  // timeout: do housekeeping
///     if (!req->status.ok()) {                             // undecodable: answer Error
///       server.reply(req->peer, makeError(req->status, req->message.envelope().sequence()));
///       continue;
///     }
///     Status s = validate(req->message, expectation);      // validate.h
///     ...
///     server.reply(req->peer, std::move(answer));          // answer.sequence = request's
///   }
/// @endcode
/// Client side (e.g. the CFD adapter or the orchestrator):
/// @code
///   Client client;
///   client.connect(ep);
///   Message welcome = client.request(makeHello(v1::ROLE_CFD, "0.1.0"), 5s);
///   expectType(welcome, v1::MESSAGE_TYPE_WELCOME);   // throws PeerError on Reject/Error
/// @endcode
///
/// Rules:
/// * `Server::bind` refuses (ProtocolError SECURITY) a non-loopback endpoint (anything other
///   than tcp://127.x.x.x, tcp://localhost, tcp://[::1], ipc://, inproc://) unless CURVE keys
///   are given in the options (docs/architecture.md).
/// * Every wait has a deadline. ZeroMQ heartbeats (ZMQ_HEARTBEAT_IVL/TIMEOUT/TTL) detect dead
///   peers at the socket level; `Client::request` throws TimeoutError naming the endpoint and
///   the awaited reply when the deadline passes.
/// * zmq::error_t never escapes: it becomes TransportError (or a Status).
/// * A Server or Client is used from one thread at a time.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <coredem/protocol/message.h>
#include <coredem/protocol/status.h>

namespace coredem::protocol {

/// CURVE keys, Z85-encoded (40 characters each). Server: serverSecretKey (+serverPublicKey).
/// Client: serverPublicKey + clientPublicKey + clientSecretKey.
struct CurveKeys {
  std::string serverPublicKey;
  std::string serverSecretKey;
  std::string clientPublicKey;
  std::string clientSecretKey;
  /// Server only: the client public keys (Z85) allowed to connect, like ssh
  /// `authorized_keys`. Non-empty: a ZAP handler admits only these keys (any other client's
  /// CURVE handshake fails, no message of it arrives) and each Request carries its client's
  /// key. Empty: any client that knows the server's public key is admitted.
  std::vector<std::string> allowedClientKeys;
  [[nodiscard]] bool serverConfigured() const { return !serverSecretKey.empty(); }
  [[nodiscard]] bool clientConfigured() const {
    return !serverPublicKey.empty() && !clientPublicKey.empty() && !clientSecretKey.empty();
  }
};

/// Generates a CURVE key pair {public, secret} (Z85); throws ProtocolError(UNSUPPORTED) if
/// libzmq was built without CURVE.
std::pair<std::string, std::string> generateCurveKeyPair();

/// Reads a persistent client key pair {public, secret} (Z85) for a server with an allow-list
/// (`coredem-dem --client-keys`): `path` is the secret key file `client.secret` that
/// `coredem-dem --generate-client-key DIR` wrote, or that DIR. The public key is derived from
/// the secret one (and checked against `client.public` next to it when that file exists).
/// Throws ProtocolError(SECURITY) naming the file when it cannot be read, is not a Z85 key,
/// does not match its public key, or can be read by group or others (like ssh, a secret key
/// must be private: chmod 600).
std::pair<std::string, std::string> readClientKeyPair(const std::string& path);

/// Reads an allow-list of client public keys: one Z85 key (40 characters) per line, then
/// optional free text (a name); blank lines and lines starting with '#' are skipped. Throws
/// ProtocolError(SECURITY) naming the file and line of a malformed key.
std::vector<std::string> readAllowedClientKeys(const std::string& path);

/// Default largest message part (frame) any socket accepts: 256 MiB, e.g. one float64 array of
/// 11 million cells x 3 components. A peer that announces a larger frame is disconnected by
/// ZeroMQ before anything is allocated (ZMQ_MAXMSGSIZE).
inline constexpr std::int64_t kDefaultMaxMessageBytes = std::int64_t{256} << 20;
/// Most frames one message may have (envelope + arrays); more: the message is refused.
inline constexpr std::size_t kMaxFramesPerMessage = 1024;

struct TransportOptions {
  /// ZMQ_HEARTBEAT_IVL: ping the peer after this much silence.
  std::chrono::milliseconds heartbeatInterval{1000};
  /// ZMQ_HEARTBEAT_TIMEOUT / TTL: drop the connection after this much silence.
  std::chrono::milliseconds heartbeatTimeout{10000};
  /// How long closing a socket may wait to flush pending outgoing messages.
  std::chrono::milliseconds linger{2000};
  /// CURVE encryption (required for non-loopback binds).
  CurveKeys curve;
  /// Server only: allow a non-loopback bind without CURVE (an explicit user opt-out, e.g.
  /// `coredem-dem --insecure` on a trusted network). Default: refuse.
  bool allowInsecure = false;
  /// ZMQ_MAXMSGSIZE on every socket: the largest frame accepted (a larger one drops the
  /// connection before it is read). A server also refuses a message whose frames together
  /// exceed it (BYTE_LENGTH) or that has more than kMaxFramesPerMessage frames. <= 0: no limit.
  std::int64_t maxMessageBytes = kDefaultMaxMessageBytes;
  /// Client only: the ZeroMQ routing id this connection presents (ZMQ_ROUTING_ID, 1-255
  /// bytes; empty: the server assigns one). For tests of routing-id reuse.
  std::string routingId;
  /// Free text put into Envelope.sender of outgoing messages when empty.
  std::string sender;
};

/// Decides where an incoming array frame goes. Called once per array with its descriptor
/// (already checked against the frame size); return a buffer of at least
/// descriptor.byte_length() bytes to receive the frame there (one copy, frame released
/// at once), or an empty span to keep the frame as is (zero copy).
using BufferProvider = std::function<std::span<std::byte>(const v1::ArrayDescriptor&)>;

struct ReceiveOptions {
  BufferProvider buffers; ///< optional
};

/// Opaque identity of a connected client (ZeroMQ routing id).
using PeerId = std::string;

/// One request received by a Server.
struct Request {
  PeerId peer;
  /// The client's CURVE public key (Z85) as authenticated by the ZAP handler, when the server
  /// has an allow-list (CurveKeys::allowedClientKeys); empty otherwise.
  std::string clientKey;
  Message message;
  /// Structural decode result (Message::decode): if not ok, answer with makeError(status).
  Status status;
};

/// True for tcp://127.x.x.x:*, tcp://localhost:*, tcp://[::1]:*, ipc://..., inproc://...
bool isLoopbackEndpoint(std::string_view endpoint);

/// ROUTER socket serving several clients.
class Server {
public:
  explicit Server(TransportOptions options = {});
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;
  Server(Server&&) noexcept;
  Server& operator=(Server&&) noexcept;

  /// Binds and returns the bound endpoint (with the actual port for "tcp://127.0.0.1:*").
  /// May be called several times (e.g. tcp and ipc). Throws ProtocolError(SECURITY) for a
  /// non-loopback endpoint without CURVE keys, TransportError if the bind fails.
  std::string bind(const std::string& endpoint);
  /// The last bound endpoint ("" before bind).
  [[nodiscard]] std::string endpoint() const;

  /// Waits up to `timeout` for the next request; nullopt on timeout. Never throws on bad
  /// input: undecodable messages come back with a non-ok Request::status.
  std::optional<Request> receive(std::chrono::milliseconds timeout,
                                 const ReceiveOptions& options = {});
  /// Peers whose connection closed since the last call (socket monitor; a peer is known once
  /// it has sent a message). A routing id is never reused while its connection is open, so
  /// a session bound to a routing id ends here when that connection closes. Keeps the last
  /// 4096 until asked. inproc connections are not watched (they have no file descriptor).
  std::vector<PeerId> takeDisconnected();
  /// Sends `message` to `peer`. Non-blocking; a vanished peer's reply is dropped (logged).
  /// Fills in Envelope.sender when empty.
  void reply(const PeerId& peer, Message message);
  /// Sends raw frames to `peer` (tests).
  void replyFrames(const PeerId& peer, const Frames& frames);

private:
  struct Impl;
  std::unique_ptr<Impl> _impl;
};

/// DEALER socket talking to one server.
class Client {
public:
  explicit Client(TransportOptions options = {});
  ~Client();
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;
  Client(Client&&) noexcept;
  Client& operator=(Client&&) noexcept;

  /// Connects (asynchronously: the first request waits for the connection within its
  /// deadline). Throws TransportError for a malformed endpoint.
  void connect(const std::string& endpoint);
  [[nodiscard]] std::string endpoint() const;

  /// Sends `message` and waits up to `timeout` for the reply with the same sequence number
  /// (or an Error reply with sequence 0). Assigns the next sequence number when the message's
  /// is 0. Stale replies to earlier timed-out requests are discarded. Returns the reply
  /// whatever its type (use expectType()); throws TimeoutError naming the endpoint and what
  /// was awaited. `options.buffers` is applied to the returned reply only (never to
  /// discarded stale replies).
  Message request(Message message, std::chrono::milliseconds timeout,
                  const ReceiveOptions& options = {});

  /// Asynchronous form: send now (returns the sequence used) ...
  std::uint64_t send(Message message);
  /// ... and collect the next reply later (nullopt on timeout). Decode problems of a reply
  /// are reported via `status` when given, else thrown as ProtocolError.
  std::optional<Message> receive(std::chrono::milliseconds timeout,
                                 const ReceiveOptions& options = {}, Status* status = nullptr);
  /// Sends raw frames (tests: garbage, truncated or inconsistent messages).
  void sendFrames(const Frames& frames);

  /// The sequence number the next send() will use when the message has none.
  [[nodiscard]] std::uint64_t nextSequence() const;

private:
  struct Impl;
  std::unique_ptr<Impl> _impl;
};

} // namespace coredem::protocol
