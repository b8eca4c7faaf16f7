#include <algorithm>

#include <coredem/protocol/status.h>

namespace coredem::protocol {

namespace {
std::string stripPrefix(const std::string& name, std::string_view prefix) {
  if (name.compare(0, prefix.size(), prefix) == 0) {
    return name.substr(prefix.size());
  }
  return name;
}
} // namespace

std::string errorCodeName(v1::ErrorCode code) {
  if (!v1::ErrorCode_IsValid(code)) {
    return "UNKNOWN_ERROR_CODE_" + std::to_string(static_cast<int>(code));
  }
  return stripPrefix(v1::ErrorCode_Name(code), "ERROR_CODE_");
}

std::string messageTypeName(v1::MessageType type) {
  if (!v1::MessageType_IsValid(type)) {
    return "UNKNOWN_TYPE_" + std::to_string(static_cast<int>(type));
  }
  return stripPrefix(v1::MessageType_Name(type), "MESSAGE_TYPE_");
}

std::string printable(std::string_view text, std::size_t maxBytes) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  const std::size_t n = std::min(text.size(), maxBytes);
  out.reserve(n + 24);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    switch (c) {
    case '\n':
      out += "\\n";
      break;
    case '\r':
      out += "\\r";
      break;
    case '\t':
      out += "\\t";
      break;
    case '\\':
      out += "\\\\";
      break;
    case '"':
      out += "\\\"";
      break;
    default:
      if (c >= 0x20 && c < 0x7f) {
        out += static_cast<char>(c);
      } else {
        out += "\\x";
        out += kHex[c >> 4];
        out += kHex[c & 0xf];
      }
    }
  }
  if (text.size() > n) {
    out += "...(" + std::to_string(text.size()) + " bytes)";
  }
  return out;
}

std::string Status::toString() const {
  if (ok()) {
    return "OK";
  }
  return errorCodeName(code) + ": " + message;
}

} // namespace coredem::protocol
