#pragma once
// The texts of the DEM server's replies: peer-supplied strings escaped and length-capped for log
// lines and replies, and a refusal (the error code and text of an Error or Reject reply).
#include <string>
#include <string_view>

#include "coredem/common/format.h"
#include "coredem/protocol/protocol.h"

namespace coredem::server {

namespace v1 = coredem::v1;

/// A peer-supplied string for a log line or a reply (escaped, length-capped).
inline std::string safe(std::string_view text, std::size_t maxBytes = 120) {
  return protocol::printable(text, maxBytes);
}

/// A connection's routing id in hex (the name of a peer that has not said Hello).
inline std::string hexPeer(const protocol::PeerId& p) {
  std::string s;
  for (unsigned char ch : p) {
    s += fmt::format("{:02x}", ch);
  }
  return s;
}

/// Why a request is refused: the code and text of its Error (or Reject) reply.
struct Refusal {
  v1::ErrorCode code = v1::ERROR_CODE_NONE;
  std::string text;
};

} // namespace coredem::server
