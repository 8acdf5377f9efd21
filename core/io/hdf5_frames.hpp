#pragma once
// HDF5 frames and checkpoints, written through the store's field registry so that no field is forgotten.
//
// A frame file holds one group (named like "frame_000012") with one dataset per particle field (named
// after the field: "position" N x D (D = 2 or 3), "density" N, "level" N, ...) for every fluid and wall particle (not ghosts, not
// halos), in id order, each with a `units` attribute (the field's unit, ParticleStore), and the attributes time,
// time_units ("s"), step, frame and particles. A checkpoint file holds group "checkpoint" with every field
// (with units too) and the whole state needed to continue bitwise identically. Every file
// is written under a temporary name and renamed when complete (core/io/atomic_file.hpp).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/particle_store.hpp"
#include "parallel/comm.hpp"

namespace sph::io {

/// How one field is stored, as XDMF needs it: NumberType, Precision (bytes) and components per particle.
struct FieldLayout {
  std::string name;
  std::string number_type;  // "Float", "Int", "UInt", "UChar"
  int precision = 8;
  int components = 1;
  bool operator==(const FieldLayout&) const = default;
};

struct FrameHeader {
  std::string group;
  double time = 0.0;
  std::uint64_t step = 0;
  std::uint64_t index = 0;
  std::uint64_t particles = 0;
  std::vector<FieldLayout> fields;
};

/// The layout of every field of a D-dimensional store (in registry order).
std::vector<FieldLayout> field_layouts(int dimension = 2);

/// Writes the named fields (every field when empty; "position" always) of every fluid and wall particle to a new
/// HDF5 file, atomically. Returns what it wrote. With `comm` across ranks (collective): every rank's own fluid and
/// the wall particles (which every rank holds) once, redistributed so that each rank writes a run of ids, all
/// ranks at once with parallel HDF5: the file is the one a single process writes.
template <int D>
FrameHeader write_frame(const std::filesystem::path& file, const std::string& group, const ParticleStore<D>& store,
                        double time, std::uint64_t step, std::uint64_t index, const std::vector<std::string>& fields,
                        const par::Comm* comm = nullptr);

/// The attributes and the datasets of a frame group (its dimension read from the position dataset).
FrameHeader read_frame_header(const std::filesystem::path& file, const std::string& group);

/// Reads one field of a frame: doubles (position and velocity come as x0, y0, [z0,] x1, y1, ...).
std::vector<double> read_frame_field(const std::filesystem::path& file, const std::string& group, const std::string& field);

/// Everything a checkpoint restores besides the particles.
struct CheckpointState {
  double time = 0.0;
  std::uint64_t step = 0;
  double dt = 0.0;
  std::uint64_t next_id = 0;
  std::uint64_t next_row = 0;    // the time-series row counter of the run
  std::uint64_t next_frame = 0;  // the frame time slot of the run (next frame at next_frame * interval)
  std::uint64_t frame_count = 0; // frames written (the next frame file's number)
  std::uint64_t next_checkpoint = 0;
  std::uint64_t particle_steps = 0;
  std::uint64_t fine_steps = 0;   // Simulation::fine_step_count (absent before per-level steps: = step)
  double initial_mass = 0.0;      // the run's state at t = 0, for the drift in the summary
  double initial_momentum_x = 0.0;
  double initial_momentum_y = 0.0;
  double initial_momentum_z = 0.0;  // 3D only
  std::uint64_t removed_particles = 0;     // fluid removed through the open top so far (Simulation::removed)
  // Its mass as the exact sum's parts (par::ExactSum::parts), so a resumed run adds later removals exactly as the
  // uninterrupted one does.
  std::vector<double> removed_mass_parts;
  std::string scene;             // the scene (JSON) the run was started from
};

/// Writes every field of every fluid and wall particle and the state, atomically; with `comm`, collectively as
/// write_frame (the file is the one-process file, and resumes at any rank count).
template <int D>
void write_checkpoint(const std::filesystem::path& file, const ParticleStore<D>& store, const CheckpointState& state,
                      const par::Comm* comm = nullptr);

/// Why `file` is not a checkpoint this program reads ("" when it is one: an HDF5 file with the checkpoint
/// group in the current format). Reads only the file's header.
std::string checkpoint_problem(const std::filesystem::path& file);

/// The dimension a checkpoint was written in (2 for checkpoints older than 3D).
int checkpoint_dimension(const std::filesystem::path& file);

/// Reads a checkpoint into `store` (replacing its particles and next id). Throws std::runtime_error, also when
/// the checkpoint was written in another dimension. With `comm` of several ranks, each rank reads only its slab of
/// the rows (rank r of P: rows [r n / P, (r + 1) n / P)), and the wall particles of every slab are shared so that
/// every rank holds them all: the ranks hold the fluid once between them (SimulationT::distribute(comm, false) then
/// sends it to its owners). Collective then.
template <int D>
CheckpointState read_checkpoint(const std::filesystem::path& file, ParticleStore<D>& store,
                                const par::Comm* comm = nullptr);

}  // namespace sph::io
