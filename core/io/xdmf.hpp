#pragma once
// The XDMF index of a run's frames: a temporal collection of point sets (one Polyvertex grid per frame,
// geometry XY from the frame's "position" dataset, every other dataset a node attribute), which ParaView
// opens as a time series. Rewritten atomically after each frame, so it only ever lists finished frames.
#include <filesystem>
#include <string>
#include <vector>

#include "core/io/hdf5_frames.hpp"

namespace sph::io {

struct XdmfEntry {
  std::string file;  // the frame's HDF5 file, relative to the XDMF file
  FrameHeader frame;
};

/// The XDMF document listing the frames in order.
std::string xdmf_document(const std::vector<XdmfEntry>& frames);

/// Writes the document atomically.
void write_xdmf(const std::filesystem::path& file, const std::vector<XdmfEntry>& frames);

}  // namespace sph::io
