#pragma once
/// @file
/// `Message`: one protocol message = an `v1::Envelope` (frame 0) + named raw arrays (frames 1..k).
///
/// Building and sending (arrays are copied once into the message, or shared without copy):
/// @code
///   using namespace coredem::protocol;
///   Message m = makeGasFields(/*step*/ 7, /*time*/ 0.07, /*dt*/ 0.01, cells, nSpecies);
///   m.addArray(fields::kGasTemperature, std::span<const double>(tGas), {cells});
///   m.addArrayShared(fields::kGasVelocity, pinnedOwner /* shared_ptr keeps memory alive */,
///                    std::span<const double>(uPtr, 3 * cells), {cells, 3});   // zero copy
///   Message reply = client.request(std::move(m), std::chrono::seconds(30));
/// @endcode
///
/// Reading a received message (no copy: views point into the received ZeroMQ frames, which
/// the Message keeps alive):
/// @code
///   std::span<const double> eps = reply.values<double>(fields::kVoidFraction);
///   reply.copyArrayTo(fields::kDragCoefficient, std::as_writable_bytes(std::span(myPinned, n)));
/// @endcode
/// To receive straight into caller-provided (e.g. pinned) buffers, pass a `BufferProvider`
/// in `ReceiveOptions` (transport.h): each array frame is then copied exactly once, into the
/// caller's buffer, and the ZeroMQ frame is released at once; views then point there.
///
/// Received arrays are always at least 8-byte aligned (misaligned frames are copied once).
/// A Message is move-only; it is not thread-safe.

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <coredem/protocol/message_types.h>
#include <coredem/protocol/status.h>
#include <coredem/v1/envelope.pb.h>

namespace coredem::protocol {

/// Bytes per element of a dtype; 0 for DTYPE_UNSPECIFIED or an unknown value.
std::size_t dtypeSize(v1::DType dtype);
/// "float64", "int32", ...
std::string dtypeName(v1::DType dtype);

/// The DType of a C++ element type.
template <class T>
constexpr v1::DType dtypeOf();
template <>
constexpr v1::DType dtypeOf<double>() {
  return v1::DTYPE_FLOAT64;
}
template <>
constexpr v1::DType dtypeOf<float>() {
  return v1::DTYPE_FLOAT32;
}
template <>
constexpr v1::DType dtypeOf<std::int32_t>() {
  return v1::DTYPE_INT32;
}
template <>
constexpr v1::DType dtypeOf<std::int64_t>() {
  return v1::DTYPE_INT64;
}
template <>
constexpr v1::DType dtypeOf<std::uint8_t>() {
  return v1::DTYPE_UINT8;
}
template <>
constexpr v1::DType dtypeOf<std::uint32_t>() {
  return v1::DTYPE_UINT32;
}
template <>
constexpr v1::DType dtypeOf<std::uint64_t>() {
  return v1::DTYPE_UINT64;
}

/// Read-only view of one array of a message. Valid while the Message (or the message it was
/// moved into: moving does not relocate array data) lives; with a BufferProvider, while the
/// caller's buffer lives.
struct ArrayView {
  const v1::ArrayDescriptor* descriptor = nullptr;
  std::span<const std::byte> bytes;

  [[nodiscard]] const std::string& name() const { return descriptor->name(); }
  [[nodiscard]] v1::DType dtype() const { return descriptor->dtype(); }
  [[nodiscard]] std::vector<std::uint64_t> shape() const {
    return {descriptor->shape().begin(), descriptor->shape().end()};
  }
  /// Typed view; throws ProtocolError(ERROR_CODE_DTYPE) if T does not match the dtype.
  template <class T>
  [[nodiscard]] std::span<const T> as() const {
    checkDtype(dtypeOf<T>());
    return {reinterpret_cast<const T*>(bytes.data()), bytes.size() / sizeof(T)};
  }

private:
  void checkDtype(v1::DType wanted) const;
};

/// A raw multipart message as bytes: frame 0 = serialized Envelope, frames 1..k = arrays.
/// Used for golden files, tests and the bad-input tests (any bytes can be sent as frames).
using Frames = std::vector<std::string>;

class Message {
public:
  /// An empty message of type MESSAGE_TYPE_UNSPECIFIED.
  Message();
  /// A message with the given type and no body (set the body with setBody or envelope()).
  explicit Message(v1::MessageType type);
  /// A message with a copy of the given envelope and no arrays; the envelope's array
  /// descriptors are cleared (arrays are added with addArray*).
  explicit Message(const v1::Envelope& envelope);
  ~Message();
  Message(Message&&) noexcept;
  Message& operator=(Message&&) noexcept;
  Message(const Message&) = delete;
  Message& operator=(const Message&) = delete;

  // ---- envelope ------------------------------------------------------------------------
  [[nodiscard]] v1::MessageType type() const;
  [[nodiscard]] const v1::Envelope& envelope() const;
  /// Mutable envelope (session id, sequence, step, time, body). Do not edit `arrays` here.
  v1::Envelope& envelope();

  Message& setSessionId(std::string id);
  Message& setSequence(std::uint64_t sequence);
  Message& setStep(std::int64_t step);
  Message& setTime(double time);

  /// Set the body and the matching Envelope.type in one call (one overload per row of
  /// COREDEM_PROTOCOL_MESSAGES, message_types.h).
#define COREDEM_PROTOCOL_SET_BODY_DECL(Body, field, TYPE) Message& setBody(const v1::Body& body);
  COREDEM_PROTOCOL_MESSAGES(COREDEM_PROTOCOL_SET_BODY_DECL)
#undef COREDEM_PROTOCOL_SET_BODY_DECL

  // ---- arrays (sending) ----------------------------------------------------------------
  /// Adds an array, copying `data` into the message. shape must satisfy
  /// prod(shape) == data.size() (throws UserError otherwise). Names must be unique.
  template <class T>
  Message& addArray(std::string_view name, std::span<const T> data,
                    std::vector<std::uint64_t> shape) {
    return addArrayBytes(name, dtypeOf<T>(), std::move(shape), std::as_bytes(data));
  }
  template <class T>
  Message& addArray(std::string_view name, const std::vector<T>& data,
                    std::vector<std::uint64_t> shape) {
    return addArray(name, std::span<const T>(data), std::move(shape));
  }
  /// Adds an array without copying: `owner` keeps `data` alive until ZeroMQ has sent it
  /// (possibly after send() returns). Use it for large or pinned buffers.
  template <class T>
  Message& addArrayShared(std::string_view name, std::shared_ptr<const void> owner,
                          std::span<const T> data, std::vector<std::uint64_t> shape) {
    return addArraySharedBytes(name, dtypeOf<T>(), std::move(shape), std::move(owner),
                               std::as_bytes(data));
  }
  /// Untyped forms of the above. byte_length = bytes.size() must equal
  /// prod(shape) * dtypeSize(dtype).
  Message& addArrayBytes(std::string_view name, v1::DType dtype, std::vector<std::uint64_t> shape,
                         std::span<const std::byte> bytes);
  Message& addArraySharedBytes(std::string_view name, v1::DType dtype,
                               std::vector<std::uint64_t> shape, std::shared_ptr<const void> owner,
                               std::span<const std::byte> bytes);

  // ---- arrays (reading) ----------------------------------------------------------------
  [[nodiscard]] std::size_t arrayCount() const;
  /// The i-th array (descriptor i + frame i+1). @pre i < arrayCount()
  [[nodiscard]] ArrayView array(std::size_t i) const;
  [[nodiscard]] std::optional<ArrayView> findArray(std::string_view name) const;
  /// The named array; throws ProtocolError(ERROR_CODE_MISSING_FIELD) if absent.
  [[nodiscard]] ArrayView array(std::string_view name) const;
  /// Typed values of the named array (checks presence and dtype).
  template <class T>
  [[nodiscard]] std::span<const T> values(std::string_view name) const {
    return array(name).as<T>();
  }
  /// Copies the named array into `destination` (e.g. a pinned buffer).
  /// @pre destination.size() >= the array's byte length (throws UserError otherwise)
  void copyArrayTo(std::string_view name, std::span<std::byte> destination) const;
  /// Sum of all array byte lengths.
  [[nodiscard]] std::uint64_t payloadBytes() const;

  // ---- codec ---------------------------------------------------------------------------
  /// The wire frames (copies the arrays; the transport itself sends without this copy).
  /// Serialization is deterministic (same message -> same bytes).
  [[nodiscard]] Frames encode() const;
  /// Decodes frames into a message and checks the structure: frame 0 parses as an Envelope
  /// (MALFORMED_ENVELOPE), frame count == 1 + descriptor count (FRAME_COUNT), each frame's
  /// size == its byte_length == prod(shape)*dtypeSize (BYTE_LENGTH, DTYPE). On failure the
  /// returned status says what is wrong; the message then holds whatever could be parsed.
  static Message decode(Frames frames, Status* status);

  struct Impl;

private:
  friend struct MessageAccess; // the transport implementation (src/), not part of the API
  std::unique_ptr<Impl> _impl;
};

// ---- typed builders ---------------------------------------------------------------------
// Each returns a Message whose type and body are set; session id, sequence, step and time
// are left for the caller (Client::request fills in the sequence when it is 0).

/// Hello announcing `role` and the protocol version `version` (default: this build's).
Message makeHello(v1::Role role, std::string softwareVersion,
                  std::vector<std::string> capabilities = {},
                  std::vector<v1::FieldManifestEntry> manifest = {});
Message makeHello(v1::Role role, std::string softwareVersion, std::uint32_t major,
                  std::uint32_t minor);
Message makeWelcome(v1::Role serverRole, std::string softwareVersion, std::uint32_t major,
                    std::uint32_t agreedMinor, std::string sessionId);
Message makeReject(v1::ErrorCode code, std::string reason);
Message makeConfigure(const v1::Configure& configure);
Message makeConfigured(std::uint64_t cells, std::uint64_t particles, std::uint32_t species,
                       std::uint32_t nSub, double dtDem);
/// GasFields header; add the arrays of fields::gasFields() with addArray*.
Message makeGasFields(std::int64_t step, double time, double dt, std::uint64_t cells,
                      std::uint32_t species);
/// Sources header; add the arrays of fields::sourceFields() with addArray*.
Message makeSources(std::int64_t step, double time, double dt, std::uint64_t cells,
                    std::uint32_t species, std::uint32_t substeps);
Message makeStepGrant(std::int64_t step, double time, double dtCfd, std::uint32_t nSub,
                      double dtDem);
Message makeStepDone(std::int64_t step, double time, const v1::StepDone& body);
Message makeCheckpointRequest(std::int64_t step, std::string directory, std::string tag = {});
/// StepGrant.checkpoint.tag asking the CFD participant to write its output fields after the
/// step (a synchronized output, docs/protocol.md): with an empty directory the grant asks for
/// the output alone, with a directory for a checkpoint as well. A participant that does not
/// know the tag sees no checkpoint request (empty directory) and writes nothing.
inline constexpr const char* kOutputTag = "output";
Message makeCheckpointDone(std::int64_t step, std::string directory,
                           std::vector<std::string> files);
Message makeHeartbeat(std::string state = {});
/// Error reply; `offendingSequence`/`offendingType` describe the refused request.
Message makeError(v1::ErrorCode code, std::string message, std::uint64_t offendingSequence = 0,
                  v1::MessageType offendingType = v1::MESSAGE_TYPE_UNSPECIFIED);
Message makeError(const Status& status, std::uint64_t offendingSequence = 0,
                  v1::MessageType offendingType = v1::MESSAGE_TYPE_UNSPECIFIED);
Message makeShutdown(std::string reason = {});
Message makeAck(std::string note = {});

/// Throws PeerError if `reply` is an Error or Reject (carrying the peer's code and message),
/// ProtocolError(UNEXPECTED_MESSAGE) if it is of another type than `expected`.
void expectType(const Message& reply, v1::MessageType expected);

/// Ledger helpers: append ("name", value) to a repeated NamedValue field.
void addNamedValue(google::protobuf::RepeatedPtrField<v1::NamedValue>* list, std::string name,
                   double value);
/// Value of `name` in a NamedValue list, or nullopt.
std::optional<double> findNamedValue(const google::protobuf::RepeatedPtrField<v1::NamedValue>& list,
                                     std::string_view name);

/// Material defaults of docs/physics.md §2: k_t/k_n = 2/7 and eta_t/eta_n = 1/2 when unset.
double ktFactor(const v1::Material& material);
double etatFactor(const v1::Material& material);

} // namespace coredem::protocol
