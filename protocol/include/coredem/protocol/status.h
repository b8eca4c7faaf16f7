#pragma once
/// @file
/// Status values and typed errors of the protocol layer.
///
/// Receiving code never throws on bad input: it returns a `Status` whose `code` is one of the
/// `coredem::v1::ErrorCode` values and whose `message` says what was wrong and what to do; a
/// server sends it back as an `Error{code, message}` reply. Calls that cannot return a status
/// (a request that timed out, a socket that cannot be bound) throw `ProtocolError` or one of
/// its subclasses; those derive from `coredem::UserError`, so `catch (const UserError&)` at a
/// program's top level reports them.

#include <string>
#include <string_view>

#include <coredem/common/check.h>
#include <coredem/v1/common.pb.h>

namespace coredem::protocol {

/// Result of decoding or validating a message. Default-constructed = success.
struct Status {
  v1::ErrorCode code = v1::ERROR_CODE_NONE;
  std::string message;

  [[nodiscard]] bool ok() const { return code == v1::ERROR_CODE_NONE; }
  explicit operator bool() const { return ok(); }

  static Status success() { return {}; }
  static Status error(v1::ErrorCode code, std::string message) {
    return Status{code, std::move(message)};
  }
  /// "SHAPE: GasFields array 'T_g' ..." (code name without the ERROR_CODE_ prefix).
  [[nodiscard]] std::string toString() const;
};

/// Short name of an error code without the "ERROR_CODE_" prefix, e.g. "NON_FINITE".
std::string errorCodeName(v1::ErrorCode code);
/// Short name of a message type without the "MESSAGE_TYPE_" prefix, e.g. "GAS_FIELDS".
std::string messageTypeName(v1::MessageType type);

/// A peer-supplied string made safe for a log line or a reply: control characters, quotes
/// and backslashes are escaped (\n, \t, \xNN, \", \\), bytes outside printable ASCII are
/// written as \xNN, and the result is cut after `maxBytes` input bytes with "...(N bytes)"
/// appended. A newline in a peer's name can therefore never forge a log line, and a 1 MB name
/// is echoed as a 160-byte prefix.
std::string printable(std::string_view peerText, std::size_t maxBytes = 160);

/// A protocol failure with its error code.
class ProtocolError : public UserError {
public:
  ProtocolError(v1::ErrorCode code, const std::string& message)
      : UserError(message)
      , _code(code) {}
  explicit ProtocolError(const Status& status)
      : ProtocolError(status.code, status.message) {}
  [[nodiscard]] v1::ErrorCode code() const { return _code; }

private:
  v1::ErrorCode _code;
};

/// No reply arrived before the deadline. what() names the endpoint and what was awaited.
class TimeoutError : public ProtocolError {
public:
  TimeoutError(std::string endpoint, std::string awaited, const std::string& message)
      : ProtocolError(v1::ERROR_CODE_TIMEOUT, message)
      , _endpoint(std::move(endpoint))
      , _awaited(std::move(awaited)) {}
  [[nodiscard]] const std::string& endpoint() const { return _endpoint; }
  [[nodiscard]] const std::string& awaited() const { return _awaited; }

private:
  std::string _endpoint;
  std::string _awaited;
};

/// A ZeroMQ call failed (the zmq::error_t is caught at the boundary and turned into this).
class TransportError : public ProtocolError {
public:
  explicit TransportError(const std::string& message)
      : ProtocolError(v1::ERROR_CODE_TRANSPORT, message) {}
};

/// The peer answered with `Error{code, message}` (or `Reject`) where another reply was
/// expected; code() is the peer's code, what() contains the peer's message.
class PeerError : public ProtocolError {
public:
  PeerError(v1::ErrorCode peerCode, const std::string& message)
      : ProtocolError(peerCode, message) {}
};

} // namespace coredem::protocol
