#pragma once
/// @file
/// The one table of coupling-protocol message types. A row names the body message of
/// `messages.proto`, its field in `Envelope.body` and its `MessageType` value (without the
/// MESSAGE_TYPE_ prefix). From it come Message::setBody(), the type ↔ body check of
/// validate(), the per-type traits below and the name of its golden file (`<field>.cdmf`).
/// tests/unit/protocol/message_types_test.cpp checks the table against the .proto files by
/// reflection, so a message type or body missing here fails the build's tests.
///
/// Adding a message: the body in messages.proto + its MessageType value (common.proto) + its
/// Envelope.body field (envelope.proto), one row here, a golden message in
/// protocol/tools/golden_gen.cpp (and its check in the golden test), then who sends and who
/// handles it.

#include <array>
#include <string_view>

#include <coredem/v1/envelope.pb.h>

// X(BodyType, envelope_field, TYPE_SUFFIX)
#define COREDEM_PROTOCOL_MESSAGES(X)                                                               \
  X(Hello, hello, HELLO)                                                                           \
  X(Welcome, welcome, WELCOME)                                                                     \
  X(Reject, reject, REJECT)                                                                        \
  X(Configure, configure, CONFIGURE)                                                               \
  X(Configured, configured, CONFIGURED)                                                            \
  X(GasFields, gas_fields, GAS_FIELDS)                                                             \
  X(Sources, sources, SOURCES)                                                                     \
  X(StepGrant, step_grant, STEP_GRANT)                                                             \
  X(StepDone, step_done, STEP_DONE)                                                                \
  X(CheckpointRequest, checkpoint_request, CHECKPOINT_REQUEST)                                     \
  X(CheckpointDone, checkpoint_done, CHECKPOINT_DONE)                                              \
  X(Heartbeat, heartbeat, HEARTBEAT)                                                               \
  X(Error, error, ERROR)                                                                           \
  X(Shutdown, shutdown, SHUTDOWN)                                                                  \
  X(Ack, ack, ACK)

namespace coredem::protocol {

/// One row of the table at run time.
struct MessageTypeInfo {
  v1::MessageType type;
  v1::Envelope::BodyCase bodyCase;
  std::string_view field; ///< the Envelope.body field, also the golden file's name
};

#define COREDEM_PROTOCOL_INFO_ROW(Body, field, TYPE)                                               \
  MessageTypeInfo{v1::MESSAGE_TYPE_##TYPE, v1::Envelope::k##Body, #field},
inline constexpr std::array kMessageTypes = {COREDEM_PROTOCOL_MESSAGES(COREDEM_PROTOCOL_INFO_ROW)};
#undef COREDEM_PROTOCOL_INFO_ROW

/// The row of `type`, or nullptr for MESSAGE_TYPE_UNSPECIFIED and unknown values.
constexpr const MessageTypeInfo* findMessageType(v1::MessageType type) {
  for (const auto& row : kMessageTypes) {
    if (row.type == type) {
      return &row;
    }
  }
  return nullptr;
}

/// Compile-time traits of a body type: MessageTraits<v1::StepGrant>::type.
template <class Body>
struct MessageTraits;
#define COREDEM_PROTOCOL_TRAITS(Body, envelopeField, TYPE)                                         \
  template <>                                                                                      \
  struct MessageTraits<v1::Body> {                                                                 \
    static constexpr v1::MessageType type = v1::MESSAGE_TYPE_##TYPE;                               \
    static constexpr v1::Envelope::BodyCase bodyCase = v1::Envelope::k##Body;                      \
    static constexpr std::string_view field = #envelopeField;                                      \
  };
COREDEM_PROTOCOL_MESSAGES(COREDEM_PROTOCOL_TRAITS)
#undef COREDEM_PROTOCOL_TRAITS

} // namespace coredem::protocol
