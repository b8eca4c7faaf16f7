#pragma once
/// @file
/// Files that are never seen half-written: manifests, run records, timers, endpoint files.

#include <filesystem>
#include <string>

namespace coredem {

/// Writes `content` to a temporary file beside `path`, fsyncs it, renames it over `path` and
/// fsyncs the folder: a reader sees the old file or the new one, never a part. Throws
/// UserError naming the file and the system's reason.
void writeFileAtomic(const std::filesystem::path& path, const std::string& content);

/// fsync of a file or (directory = true) a folder; best effort (some file systems refuse it).
void fsyncPath(const std::filesystem::path& p, bool directory);

/// fsync of a file written by another library (e.g. HDF5) before it is renamed into place;
/// throws UserError naming the file when it cannot be flushed.
void syncFile(const std::filesystem::path& p);

} // namespace coredem
