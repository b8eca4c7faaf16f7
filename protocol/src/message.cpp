#include <chrono>
#include <cstring>
#include <limits>

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>

#include <coredem/common/check.h>
#include <coredem/protocol/version.h>

#include "message_impl.h"

namespace coredem::protocol {

std::size_t dtypeSize(v1::DType dtype) {
  switch (dtype) {
  case v1::DTYPE_FLOAT64:
  case v1::DTYPE_INT64:
  case v1::DTYPE_UINT64:
    return 8;
  case v1::DTYPE_FLOAT32:
  case v1::DTYPE_INT32:
  case v1::DTYPE_UINT32:
    return 4;
  case v1::DTYPE_UINT8:
    return 1;
  default:
    return 0;
  }
}

std::string dtypeName(v1::DType dtype) {
  switch (dtype) {
  case v1::DTYPE_FLOAT64:
    return "float64";
  case v1::DTYPE_FLOAT32:
    return "float32";
  case v1::DTYPE_INT32:
    return "int32";
  case v1::DTYPE_INT64:
    return "int64";
  case v1::DTYPE_UINT8:
    return "uint8";
  case v1::DTYPE_UINT32:
    return "uint32";
  case v1::DTYPE_UINT64:
    return "uint64";
  case v1::DTYPE_UNSPECIFIED:
    return "unspecified";
  default:
    return "unknown(" + std::to_string(static_cast<int>(dtype)) + ")";
  }
}

void ArrayView::checkDtype(v1::DType wanted) const {
  if (descriptor->dtype() != wanted) {
    throw ProtocolError(v1::ERROR_CODE_DTYPE, "array '" + printable(descriptor->name()) +
                                                  "' has dtype " + dtypeName(descriptor->dtype()) +
                                                  ", read as " + dtypeName(wanted));
  }
}

bool shapeElements(const google::protobuf::RepeatedField<std::uint64_t>& shape,
                   std::uint64_t* elements) {
  std::uint64_t n = 1;
  for (std::uint64_t d : shape) {
    if (d != 0 && n > std::numeric_limits<std::uint64_t>::max() / d) {
      return false;
    }
    n *= d;
  }
  *elements = n;
  return true;
}

namespace {

std::string shapeString(const google::protobuf::RepeatedField<std::uint64_t>& shape) {
  std::string s = "[";
  for (int i = 0; i < shape.size(); ++i) {
    if (i) {
      s += ',';
    }
    s += std::to_string(shape[i]);
  }
  return s + "]";
}

/// 8-byte aligned owned copy of `bytes`.
Buffer ownedCopy(std::span<const std::byte> bytes) {
  auto storage = std::make_shared<std::vector<std::uint64_t>>((bytes.size() + 7) / 8);
  if (!bytes.empty()) {
    std::memcpy(storage->data(), bytes.data(), bytes.size());
  }
  Buffer b;
  b.data = reinterpret_cast<const std::byte*>(storage->data());
  b.size = bytes.size();
  b.owner = std::move(storage);
  return b;
}

} // namespace

std::string serializeEnvelope(const v1::Envelope& envelope) {
  std::string out;
  {
    google::protobuf::io::StringOutputStream stream(&out);
    google::protobuf::io::CodedOutputStream coded(&stream);
    coded.SetSerializationDeterministic(true);
    const bool ok = envelope.SerializeToCodedStream(&coded);
    COREDEM_ASSERT(ok);
    (void)ok;
  }
  return out;
}

Status decodeInto(Message& out, const std::byte* envelopeData, std::size_t envelopeSize,
                  std::vector<Buffer> arrays) {
  auto& impl = MessageAccess::impl(out);
  impl.envelope.Clear();
  impl.arrays.clear();
  if (envelopeData == nullptr && envelopeSize == 0 && arrays.empty()) {
    return Status::error(v1::ERROR_CODE_MALFORMED_ENVELOPE,
                         "empty message: expected frame 0 = a serialized coredem.v1.Envelope");
  }
  if (envelopeSize > static_cast<std::size_t>(std::numeric_limits<int>::max()) ||
      !impl.envelope.ParseFromArray(envelopeData, static_cast<int>(envelopeSize))) {
    impl.envelope.Clear();
    return Status::error(v1::ERROR_CODE_MALFORMED_ENVELOPE,
                         "frame 0 (" + std::to_string(envelopeSize) +
                             " bytes) is not a valid coredem.v1.Envelope; send a serialized "
                             "Envelope as the first frame of every message");
  }
  const auto& env = impl.envelope;
  if (static_cast<std::size_t>(env.arrays_size()) != arrays.size()) {
    return Status::error(v1::ERROR_CODE_FRAME_COUNT,
                         "the envelope describes " + std::to_string(env.arrays_size()) +
                             " arrays but " + std::to_string(arrays.size()) +
                             " array frames followed it; send exactly one frame per "
                             "ArrayDescriptor, in the same order");
  }
  for (int i = 0; i < env.arrays_size(); ++i) {
    const auto& d = env.arrays(i);
    const Buffer& b = arrays[static_cast<std::size_t>(i)];
    std::size_t elem = dtypeSize(d.dtype());
    if (elem == 0) {
      return Status::error(v1::ERROR_CODE_DTYPE,
                           "array '" + printable(d.name()) + "' (frame " + std::to_string(i + 1) +
                               ") has dtype " + dtypeName(d.dtype()) +
                               ", which this protocol version does not know; use one of "
                               "float64, float32, int32, int64, uint8, uint32, uint64");
    }
    if (b.size != d.byte_length()) {
      return Status::error(v1::ERROR_CODE_BYTE_LENGTH,
                           "array '" + printable(d.name()) + "' (frame " + std::to_string(i + 1) +
                               ") has " + std::to_string(b.size) +
                               " bytes but its descriptor declares byte_length " +
                               std::to_string(d.byte_length()) +
                               "; the frame was truncated or the descriptor is wrong");
    }
    std::uint64_t elements = 0;
    if (!shapeElements(d.shape(), &elements) || elements > d.byte_length() / elem ||
        elements * elem != d.byte_length()) {
      return Status::error(
          v1::ERROR_CODE_BYTE_LENGTH,
          "array '" + printable(d.name()) + "': shape " + shapeString(d.shape()) + " of " +
              dtypeName(d.dtype()) + " needs " +
              (elements > d.byte_length() ? std::string("more than ") : std::string()) +
              std::to_string(elements * elem) + " bytes but byte_length is " +
              std::to_string(d.byte_length()) +
              "; byte_length must be prod(shape) * sizeof(dtype)");
    }
  }
  impl.arrays.reserve(arrays.size());
  for (auto& b : arrays) {
    if (reinterpret_cast<std::uintptr_t>(b.data) % 8 != 0) {
      impl.arrays.push_back(ownedCopy({b.data, b.size}));
    } else {
      impl.arrays.push_back(std::move(b));
    }
  }
  return Status::success();
}

// ---- Message ---------------------------------------------------------------------------

Message::Message()
    : _impl(std::make_unique<Impl>()) {}
Message::Message(v1::MessageType type)
    : Message() {
  _impl->envelope.set_type(type);
}
Message::Message(const v1::Envelope& envelope)
    : Message() {
  _impl->envelope = envelope;
  _impl->envelope.clear_arrays();
}
Message::~Message() = default;
Message::Message(Message&&) noexcept = default;
Message& Message::operator=(Message&&) noexcept = default;

v1::MessageType Message::type() const {
  return _impl->envelope.type();
}
const v1::Envelope& Message::envelope() const {
  return _impl->envelope;
}
v1::Envelope& Message::envelope() {
  return _impl->envelope;
}

Message& Message::setSessionId(std::string id) {
  _impl->envelope.set_session_id(std::move(id));
  return *this;
}
Message& Message::setSequence(std::uint64_t sequence) {
  _impl->envelope.set_sequence(sequence);
  return *this;
}
Message& Message::setStep(std::int64_t step) {
  _impl->envelope.set_step(step);
  return *this;
}
Message& Message::setTime(double time) {
  _impl->envelope.set_time(time);
  return *this;
}

#define COREDEM_SET_BODY(Body, field, TYPE)                                                        \
  Message& Message::setBody(const v1::Body& body) {                                                \
    *_impl->envelope.mutable_##field() = body;                                                     \
    _impl->envelope.set_type(MessageTraits<v1::Body>::type);                                       \
    return *this;                                                                                  \
  }
COREDEM_PROTOCOL_MESSAGES(COREDEM_SET_BODY)
#undef COREDEM_SET_BODY

namespace {
v1::ArrayDescriptor* addDescriptor(v1::Envelope& env, std::string_view name, v1::DType dtype,
                                   const std::vector<std::uint64_t>& shape, std::size_t bytes) {
  for (const auto& d : env.arrays()) {
    COREDEM_CHECK(d.name() != name, "array '{}' added twice to one message; names are unique",
                  name);
  }
  std::size_t elem = dtypeSize(dtype);
  COREDEM_CHECK(elem != 0, "array '{}': unknown dtype {}", name, static_cast<int>(dtype));
  std::uint64_t elements = 1;
  for (auto d : shape) {
    elements *= d;
  }
  COREDEM_CHECK(elements * elem == bytes,
                "array '{}': shape has {} elements ({} bytes of {}) but {} bytes were given", name,
                elements, elements * elem, dtypeName(dtype), bytes);
  auto* d = env.add_arrays();
  d->set_name(std::string(name));
  d->set_dtype(dtype);
  for (auto s : shape) {
    d->add_shape(s);
  }
  d->set_byte_length(bytes);
  return d;
}
} // namespace

Message& Message::addArrayBytes(std::string_view name, v1::DType dtype,
                                std::vector<std::uint64_t> shape,
                                std::span<const std::byte> bytes) {
  addDescriptor(_impl->envelope, name, dtype, shape, bytes.size());
  _impl->arrays.push_back(ownedCopy(bytes));
  return *this;
}

Message& Message::addArraySharedBytes(std::string_view name, v1::DType dtype,
                                      std::vector<std::uint64_t> shape,
                                      std::shared_ptr<const void> owner,
                                      std::span<const std::byte> bytes) {
  addDescriptor(_impl->envelope, name, dtype, shape, bytes.size());
  _impl->arrays.push_back(Buffer{std::move(owner), bytes.data(), bytes.size()});
  return *this;
}

std::size_t Message::arrayCount() const {
  return _impl->arrays.size();
}

ArrayView Message::array(std::size_t i) const {
  COREDEM_ASSERT(i < _impl->arrays.size());
  const Buffer& b = _impl->arrays[i];
  return ArrayView{&_impl->envelope.arrays(static_cast<int>(i)), {b.data, b.size}};
}

std::optional<ArrayView> Message::findArray(std::string_view name) const {
  for (std::size_t i = 0; i < _impl->arrays.size(); ++i) {
    if (_impl->envelope.arrays(static_cast<int>(i)).name() == name) {
      return array(i);
    }
  }
  return std::nullopt;
}

ArrayView Message::array(std::string_view name) const {
  auto view = findArray(name);
  if (!view) {
    throw ProtocolError(v1::ERROR_CODE_MISSING_FIELD, std::string(messageTypeName(type())) +
                                                          " message has no array '" +
                                                          std::string(name) + "'");
  }
  return *view;
}

void Message::copyArrayTo(std::string_view name, std::span<std::byte> destination) const {
  ArrayView view = array(name);
  COREDEM_CHECK(destination.size() >= view.bytes.size(),
                "copyArrayTo('{}'): destination has {} bytes, the array needs {}", name,
                destination.size(), view.bytes.size());
  if (!view.bytes.empty()) {
    std::memcpy(destination.data(), view.bytes.data(), view.bytes.size());
  }
}

std::uint64_t Message::payloadBytes() const {
  std::uint64_t total = 0;
  for (const auto& b : _impl->arrays) {
    total += b.size;
  }
  return total;
}

Frames Message::encode() const {
  Frames frames;
  frames.reserve(1 + _impl->arrays.size());
  frames.push_back(serializeEnvelope(_impl->envelope));
  for (const auto& b : _impl->arrays) {
    frames.emplace_back(reinterpret_cast<const char*>(b.data), b.size);
  }
  return frames;
}

Message Message::decode(Frames frames, Status* status) {
  Message m;
  std::vector<Buffer> arrays;
  auto keep = std::make_shared<Frames>(std::move(frames));
  for (std::size_t i = 1; i < keep->size(); ++i) {
    const std::string& f = (*keep)[i];
    arrays.push_back(Buffer{keep, reinterpret_cast<const std::byte*>(f.data()), f.size()});
  }
  Status s;
  if (keep->empty()) {
    s = decodeInto(m, nullptr, 0, {});
  } else {
    const std::string& env = keep->front();
    s = decodeInto(m, reinterpret_cast<const std::byte*>(env.data()), env.size(),
                   std::move(arrays));
  }
  if (status) {
    *status = s;
  } else if (!s.ok()) {
    throw ProtocolError(s);
  }
  return m;
}

// ---- builders --------------------------------------------------------------------------

Message makeHello(v1::Role role, std::string softwareVersion, std::vector<std::string> capabilities,
                  std::vector<v1::FieldManifestEntry> manifest) {
  Message m =
      makeHello(role, std::move(softwareVersion), kProtocolVersion.major, kProtocolVersion.minor);
  auto* h = m.envelope().mutable_hello();
  for (auto& c : capabilities) {
    h->add_capabilities(std::move(c));
  }
  for (auto& f : manifest) {
    *h->add_fields() = std::move(f);
  }
  return m;
}

Message makeHello(v1::Role role, std::string softwareVersion, std::uint32_t major,
                  std::uint32_t minor) {
  v1::Hello h;
  h.set_protocol_major(major);
  h.set_protocol_minor(minor);
  h.set_software_version(std::move(softwareVersion));
  h.set_role(role);
  Message m;
  m.setBody(h);
  return m;
}

Message makeWelcome(v1::Role serverRole, std::string softwareVersion, std::uint32_t major,
                    std::uint32_t agreedMinor, std::string sessionId) {
  v1::Welcome w;
  w.set_protocol_major(major);
  w.set_protocol_minor(agreedMinor);
  w.set_software_version(std::move(softwareVersion));
  w.set_role(serverRole);
  w.set_session_id(sessionId);
  Message m;
  m.setBody(w);
  m.setSessionId(std::move(sessionId));
  return m;
}

Message makeReject(v1::ErrorCode code, std::string reason) {
  v1::Reject r;
  r.set_code(code);
  r.set_reason(std::move(reason));
  r.set_server_protocol_major(kProtocolVersion.major);
  r.set_server_protocol_minor(kProtocolVersion.minor);
  Message m;
  m.setBody(r);
  return m;
}

Message makeConfigure(const v1::Configure& configure) {
  Message m;
  m.setBody(configure);
  m.setStep(configure.start_step());
  m.setTime(configure.start_time());
  return m;
}

Message makeConfigured(std::uint64_t cells, std::uint64_t particles, std::uint32_t species,
                       std::uint32_t nSub, double dtDem) {
  v1::Configured c;
  c.set_cell_count(cells);
  c.set_particle_count(particles);
  c.set_species_count(species);
  c.set_n_sub(nSub);
  c.set_dt_dem(dtDem);
  Message m;
  m.setBody(c);
  return m;
}

Message makeGasFields(std::int64_t step, double time, double dt, std::uint64_t cells,
                      std::uint32_t species) {
  v1::GasFields g;
  g.set_dt(dt);
  g.set_cell_count(cells);
  g.set_species_count(species);
  Message m;
  m.setBody(g).setStep(step).setTime(time);
  return m;
}

Message makeSources(std::int64_t step, double time, double dt, std::uint64_t cells,
                    std::uint32_t species, std::uint32_t substeps) {
  v1::Sources s;
  s.set_dt(dt);
  s.set_cell_count(cells);
  s.set_species_count(species);
  s.set_substeps(substeps);
  Message m;
  m.setBody(s).setStep(step).setTime(time);
  return m;
}

Message makeStepGrant(std::int64_t step, double time, double dtCfd, std::uint32_t nSub,
                      double dtDem) {
  v1::StepGrant g;
  g.set_dt_cfd(dtCfd);
  g.set_n_sub(nSub);
  g.set_dt_dem(dtDem);
  Message m;
  m.setBody(g).setStep(step).setTime(time);
  return m;
}

Message makeStepDone(std::int64_t step, double time, const v1::StepDone& body) {
  Message m;
  m.setBody(body).setStep(step).setTime(time);
  return m;
}

Message makeCheckpointRequest(std::int64_t step, std::string directory, std::string tag) {
  v1::CheckpointRequest r;
  r.set_directory(std::move(directory));
  r.set_tag(std::move(tag));
  Message m;
  m.setBody(r).setStep(step);
  return m;
}

Message makeCheckpointDone(std::int64_t step, std::string directory,
                           std::vector<std::string> files) {
  v1::CheckpointDone d;
  d.set_directory(std::move(directory));
  for (auto& f : files) {
    d.add_files(std::move(f));
  }
  Message m;
  m.setBody(d).setStep(step);
  return m;
}

Message makeHeartbeat(std::string state) {
  v1::Heartbeat h;
  h.set_unix_time(
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count());
  h.set_state(std::move(state));
  Message m;
  m.setBody(h);
  return m;
}

Message makeError(v1::ErrorCode code, std::string message, std::uint64_t offendingSequence,
                  v1::MessageType offendingType) {
  v1::Error e;
  e.set_code(code);
  e.set_message(std::move(message));
  e.set_offending_sequence(offendingSequence);
  e.set_offending_type(offendingType);
  Message m;
  m.setBody(e).setSequence(offendingSequence);
  return m;
}

Message makeError(const Status& status, std::uint64_t offendingSequence,
                  v1::MessageType offendingType) {
  return makeError(status.code, status.message, offendingSequence, offendingType);
}

Message makeShutdown(std::string reason) {
  v1::Shutdown s;
  s.set_reason(std::move(reason));
  Message m;
  m.setBody(s);
  return m;
}

Message makeAck(std::string note) {
  v1::Ack a;
  a.set_note(std::move(note));
  Message m;
  m.setBody(a);
  return m;
}

void expectType(const Message& reply, v1::MessageType expected) {
  if (reply.type() == expected) {
    return;
  }
  const auto& env = reply.envelope();
  if (reply.type() == v1::MESSAGE_TYPE_ERROR) {
    throw PeerError(env.error().code(), "peer answered Error " + errorCodeName(env.error().code()) +
                                            ": " + env.error().message());
  }
  if (reply.type() == v1::MESSAGE_TYPE_REJECT) {
    throw PeerError(env.reject().code(), "peer rejected the handshake (" +
                                             errorCodeName(env.reject().code()) +
                                             "): " + env.reject().reason());
  }
  throw ProtocolError(v1::ERROR_CODE_UNEXPECTED_MESSAGE, "expected a " + messageTypeName(expected) +
                                                             " reply but got " +
                                                             messageTypeName(reply.type()));
}

void addNamedValue(google::protobuf::RepeatedPtrField<v1::NamedValue>* list, std::string name,
                   double value) {
  auto* nv = list->Add();
  nv->set_name(std::move(name));
  nv->set_value(value);
}

std::optional<double> findNamedValue(const google::protobuf::RepeatedPtrField<v1::NamedValue>& list,
                                     std::string_view name) {
  for (const auto& nv : list) {
    if (nv.name() == name) {
      return nv.value();
    }
  }
  return std::nullopt;
}

double ktFactor(const v1::Material& material) {
  return material.has_kt_factor() ? material.kt_factor() : 2.0 / 7.0;
}

double etatFactor(const v1::Material& material) {
  return material.has_etat_factor() ? material.etat_factor() : 0.5;
}

} // namespace coredem::protocol
