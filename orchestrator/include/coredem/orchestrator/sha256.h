#pragma once
/// @file
/// SHA-256 (FIPS 180-4) of byte strings and files, used for checkpoint manifests and the
/// configuration hash. Own implementation; tested against the FIPS 180-2 example vectors.

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>

namespace coredem::orchestrator {

/// Incremental SHA-256: update() any number of times, then hexDigest() once.
class Sha256 {
public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;

  /// Feeds bytes. @pre digest()/hexDigest() not yet called.
  void update(std::span<const std::byte> bytes);
  void update(std::string_view text);

  /// Finishes the hash and returns the 32-byte digest. @post the object is finished.
  std::array<std::uint8_t, 32> digest();
  /// Finishes the hash and returns it as 64 lower-case hex characters.
  std::string hexDigest();

private:
  struct Impl;
  std::unique_ptr<Impl> _impl;
};

/// SHA-256 of a string, as 64 lower-case hex characters.
std::string sha256Hex(std::string_view text);

/// SHA-256 of a file's contents (streamed), as hex. Throws coredem::UserError if unreadable.
std::string sha256File(const std::filesystem::path& file);

} // namespace coredem::orchestrator
