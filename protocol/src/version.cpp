#include <algorithm>

#include <coredem/protocol/version.h>

namespace coredem::protocol {

std::string Version::toString() const {
  return std::to_string(major) + "." + std::to_string(minor);
}

Negotiation negotiate(Version ours, Version theirs) {
  Negotiation result;
  if (ours.major != theirs.major) {
    result.accepted = false;
    result.status = Status::error(
        v1::ERROR_CODE_VERSION,
        "protocol version mismatch: this server speaks coredem protocol " + ours.toString() +
            ", the client speaks " + theirs.toString() +
            "; major versions must be equal. Use a client and server built from the same "
            "major release (" +
            std::to_string(ours.major) + ".x).");
    return result;
  }
  result.accepted = true;
  result.agreed = Version{ours.major, std::min(ours.minor, theirs.minor)};
  return result;
}

} // namespace coredem::protocol
