#include "core/io/output_folder.hpp"

#include <cstdio>

#include "core/io/atomic_file.hpp"

namespace sph::io {

std::string RunFiles::frame_group(std::uint64_t index) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "frame_%06llu", static_cast<unsigned long long>(index));
  return buf;
}

std::string RunFiles::frame_file_name(std::uint64_t index) { return frame_group(index) + ".h5"; }

std::filesystem::path RunFiles::frame(std::uint64_t index) const { return frames() / frame_file_name(index); }

bool RunFiles::holds_run() const {
  std::error_code ec;
  for (const auto& p : {scene(), series(), xdmf(), frames(), checkpoint(), summary()}) {
    if (std::filesystem::exists(p, ec)) return true;
  }
  return false;
}

void RunFiles::clear_run() const {
  std::error_code ec;
  for (const auto& p : {scene(), series(), xdmf(), checkpoint(), summary()}) {
    std::filesystem::remove(p, ec);
    std::filesystem::remove(temporary_path(p), ec);
  }
  if (std::filesystem::is_directory(frames(), ec)) {
    for (const auto& entry : std::filesystem::directory_iterator(frames(), ec)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("frame_", 0) == 0) std::filesystem::remove(entry.path(), ec);
    }
    std::filesystem::remove(frames(), ec);  // only if now empty
  }
}

}  // namespace sph::io
