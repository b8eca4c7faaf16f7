// libFuzzer target: envelope decoding and validation of every message type, as coredem-dem
// applies them to what a peer sends (bench/fuzz/run.sh; docs/security.md "Fuzzing").
//
// Input: one multipart message in the golden-file layout (protocol/golden/README.md: "CDMF",
// uint32 version, uint32 frame count, then per frame uint64 length + bytes; lengths are cut to
// what is left, so every input means some frames); anything else is taken as a single
// envelope frame. The message is decoded (Message::decode), validated against expectations
// for each type (with and without a session, counts taken from the body and fixed ones), its
// Configure checked (validateConfigure, the server's admitConfigure with a 1 GiB budget), its
// GasFields ranges checked (validateGasRanges), and the printable/describe/error helpers
// that format it for logs and replies run on it. Oracle: no crash, no sanitizer report, and a
// message that decoded cleanly re-encodes to frames that decode cleanly again.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <google/protobuf/stubs/logging.h>

#include "admission.h"
#include "coredem/protocol/message.h"
#include "coredem/protocol/status.h"
#include "coredem/protocol/validate.h"

namespace proto = coredem::protocol;
namespace v1 = coredem::v1;

namespace {

std::uint64_t readLE(const std::uint8_t* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) {
    v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  }
  return v;
}

proto::Frames framesOf(const std::uint8_t* data, std::size_t size) {
  proto::Frames frames;
  if (size < 12 || std::memcmp(data, "CDMF", 4) != 0) {
    frames.emplace_back(reinterpret_cast<const char*>(data), size);
    return frames;
  }
  const std::uint64_t declared = readLE(data + 8, 4);
  std::size_t pos = 12;
  // At most the transport's frame limit (1024 arrays + envelope).
  for (std::uint64_t k = 0; k < declared && k < 1025 && pos + 8 <= size; ++k) {
    std::uint64_t len = readLE(data + pos, 8);
    pos += 8;
    len = std::min<std::uint64_t>(len, size - pos);
    frames.emplace_back(reinterpret_cast<const char*>(data + pos), static_cast<std::size_t>(len));
    pos += static_cast<std::size_t>(len);
  }
  return frames;
}

const std::vector<v1::MessageType>& allTypes() {
  static const std::vector<v1::MessageType> types = [] {
    std::vector<v1::MessageType> t;
    for (int i = v1::MessageType_MIN; i <= v1::MessageType_MAX; ++i) {
      if (v1::MessageType_IsValid(i) && i != v1::MESSAGE_TYPE_UNSPECIFIED) {
        t.push_back(static_cast<v1::MessageType>(i));
      }
    }
    return t;
  }();
  return types;
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  // libprotobuf logs every string field with invalid UTF-8 it refuses; not a finding.
  google::protobuf::SetLogHandler(nullptr);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  proto::Status status;
  proto::Message m = proto::Message::decode(framesOf(data, size), &status);
  (void)proto::printable(status.message, 400);
  (void)proto::makeError(status, m.envelope().sequence(), m.envelope().type());
  if (!status.ok()) {
    return 0;
  }
  const auto& env = m.envelope();
  (void)proto::messageTypeName(m.type());
  (void)proto::printable(env.sender(), 64);
  (void)proto::printable(env.session_id(), 64);
  (void)m.payloadBytes();

  // Validation as the server does it: any type, then the message's own type with the session
  // and counts the server would hold (from the body, and fixed ones).
  proto::Expectation any;
  (void)proto::validate(m, any);
  proto::Expectation e;
  e.types = {m.type()};
  e.sessionId = std::string("0123456789abcdef");
  e.sequenceAfter = 0;
  e.step = env.step();
  (void)proto::validate(m, e);
  const bool gas = m.type() == v1::MESSAGE_TYPE_GAS_FIELDS;
  const bool src = m.type() == v1::MESSAGE_TYPE_SOURCES;
  if (gas || src) {
    proto::Expectation counts;
    counts.types = {m.type()};
    counts.cells = gas ? env.gas_fields().cell_count() : env.sources().cell_count();
    counts.species = gas ? env.gas_fields().species_count() : env.sources().species_count();
    if (proto::validate(m, counts).ok() && gas) {
      (void)proto::validateGasRanges(m);
    }
    proto::Expectation fixed;
    fixed.cells = 27;
    fixed.species = 1;
    if (proto::validate(m, fixed).ok() && gas) {
      (void)proto::validateGasRanges(m);
    }
  }
  for (const auto t : allTypes()) { // the "wrong type" paths of every expectation
    proto::Expectation other;
    other.types = {t};
    (void)proto::validate(m, other);
  }
  if (m.type() == v1::MESSAGE_TYPE_CONFIGURE) {
    const auto& c = env.configure();
    const auto configured = proto::validateConfigure(c);
    (void)proto::cellCount(c.coupling_mesh());
    (void)coredem::server::admitConfigure(
        c, coredem::server::limitsFor(std::uint64_t{1} << 30, 100000));
    (void)configured;
  }

  // Oracle: a cleanly decoded message re-encodes to frames that decode cleanly.
  proto::Status again;
  (void)proto::Message::decode(m.encode(), &again);
  if (!again.ok()) {
    std::abort();
  }
  return 0;
}
