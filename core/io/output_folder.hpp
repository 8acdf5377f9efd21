#pragma once
// The files a run writes into its output folder, and the rule that a folder already holding a run is
// not overwritten unless asked (only these names are ever removed; nothing else in the folder is touched).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace sph::io {

struct RunFiles {
  std::filesystem::path folder;
  std::filesystem::path scene() const { return folder / "scene.json"; }        // the resolved scene
  std::filesystem::path series() const { return folder / "series.csv"; }       // diagnostics and probes
  std::filesystem::path xdmf() const { return folder / "frames.xdmf"; }        // ParaView index of the frames
  std::filesystem::path frames() const { return folder / "frames"; }           // frame_NNNNNN.h5
  std::filesystem::path checkpoint() const { return folder / "checkpoint.h5"; }
  std::filesystem::path summary() const { return folder / "run.json"; }        // written when the run ends
  std::filesystem::path frame(std::uint64_t index) const;
  static std::string frame_group(std::uint64_t index);                        // "frame_000012"
  static std::string frame_file_name(std::uint64_t index);                    // "frame_000012.h5"

  /// True when the folder holds any file of a run.
  bool holds_run() const;
  /// Removes the files of a previous run (and only those).
  void clear_run() const;
};

}  // namespace sph::io
