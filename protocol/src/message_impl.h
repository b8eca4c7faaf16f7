#pragma once
// Internal representation of coredem::protocol::Message, shared by message.cpp and
// transport.cpp. Not installed, not part of the API.

#include <cstddef>
#include <memory>
#include <vector>

#include <coredem/protocol/message.h>

namespace coredem::protocol {

/// One array frame: bytes kept alive by `owner` (a received ZeroMQ frame, an owned copy,
/// or the caller's shared buffer). owner may be null when the memory belongs to the caller
/// (BufferProvider).
struct Buffer {
  std::shared_ptr<const void> owner;
  const std::byte* data = nullptr;
  std::size_t size = 0;
};

struct Message::Impl {
  v1::Envelope envelope;
  std::vector<Buffer> arrays; // arrays[i] matches envelope.arrays(i)
};

struct MessageAccess {
  static Message::Impl& impl(Message& m) { return *m._impl; }
  static const Message::Impl& impl(const Message& m) { return *m._impl; }
};

/// Decodes an envelope frame and array buffers into `out` with the structural checks of
/// Message::decode. Misaligned buffers are copied to 8-byte aligned storage.
Status decodeInto(Message& out, const std::byte* envelopeData, std::size_t envelopeSize,
                  std::vector<Buffer> arrays);

/// Deterministic serialization of the envelope (frame 0).
std::string serializeEnvelope(const v1::Envelope& envelope);

/// Product of a shape; false on overflow.
bool shapeElements(const google::protobuf::RepeatedField<std::uint64_t>& shape,
                   std::uint64_t* elements);

} // namespace coredem::protocol
