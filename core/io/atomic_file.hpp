#pragma once
// Atomic writes: a file is written under a temporary name in its own folder and renamed over the final
// name only once complete, so a run killed at any moment leaves every finished file readable and never
// a half-written one under the final name.
#include <filesystem>
#include <string>

namespace sph::io {

/// The temporary name a file is written under before commit_file(): "<name>.tmp" in the same folder.
std::filesystem::path temporary_path(const std::filesystem::path& file);

/// Renames the temporary file over `file` (atomic on POSIX file systems). Throws std::runtime_error.
void commit_file(const std::filesystem::path& file);

/// Writes `content` to `file` atomically.
void write_file_atomic(const std::filesystem::path& file, const std::string& content);

/// Reads a whole file (throws std::runtime_error if it cannot).
std::string read_file(const std::filesystem::path& file);

}  // namespace sph::io
