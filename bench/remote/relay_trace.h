#pragma once
/// @file
/// Reads what `coredem-relay --trace-chunks` logs (relay.cpp writes it): one line per chunk,
///   "coredem-relay: chunk HOST:PORT up|down N bytes read_ns R due_ns D written_ns W"
/// (steady-clock nanoseconds), for the tests that check the relay's delay and bandwidth by what
/// it did rather than by the wall clock.

#include <sstream>
#include <string>
#include <vector>

namespace coredem::relay {

struct TracedChunk {
  std::string connection, direction; ///< "HOST:PORT", "up" | "down"
  long long bytes = 0, read = 0, due = 0, written = 0;
};

/// Every traced chunk of `log` in order; only those going `direction` when it is not empty.
inline std::vector<TracedChunk> tracedChunks(const std::string& log,
                                             const std::string& direction = {}) {
  static const std::string kTag = "coredem-relay: chunk ";
  std::vector<TracedChunk> out;
  std::istringstream in(log);
  for (std::string line; std::getline(in, line);) {
    const auto at = line.find(kTag);
    if (at == std::string::npos)
      continue;
    std::istringstream w(line.substr(at + kTag.size()));
    TracedChunk c;
    std::string word;
    w >> c.connection >> c.direction >> c.bytes >> word >> word >> c.read >> word >> c.due >>
        word >> c.written;
    if (direction.empty() || c.direction == direction)
      out.push_back(c);
  }
  return out;
}

} // namespace coredem::relay
