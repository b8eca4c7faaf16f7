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

std::string Status::toString() const {
  if (ok()) {
    return "OK";
  }
  return errorCodeName(code) + ": " + message;
}

} // namespace coredem::protocol
