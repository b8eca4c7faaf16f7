#pragma once
/// @file
/// On-disk container for one multipart message (used for the golden files).
///
/// Format (all integers little-endian):
///   bytes 0..3   magic "CDMF"
///   uint32       format version (1)
///   uint32       frame count k+1
///   k+1 times:   uint64 frame length L, then L bytes of the frame
/// Frame 0 is the serialized Envelope, frames 1..k the raw arrays, exactly as on the wire.

#include <filesystem>

#include <coredem/protocol/message.h>

namespace coredem::protocol {

/// Writes frames to `path` (overwrites). Throws UserError on I/O failure.
void writeMultipartFile(const std::filesystem::path& path, const Frames& frames);
/// Reads a file written by writeMultipartFile. Throws UserError naming the file and the
/// problem (bad magic, truncated, trailing bytes).
Frames readMultipartFile(const std::filesystem::path& path);

} // namespace coredem::protocol
