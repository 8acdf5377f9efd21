#include "core/io/hdf5_frames.hpp"

#include <hdf5.h>

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <type_traits>

#include "core/domain.hpp"
#include "core/io/atomic_file.hpp"

namespace sph::io {

namespace {

constexpr hid_t kDefault = 0;  // H5P_DEFAULT
constexpr const char* kCheckpointGroup = "checkpoint";
// The layout of a checkpoint: its fields are the store's registry. 2 since the store holds the jerk fields
// (time.predictor, 2026-12-02): a checkpoint of format 1 lacks them and is refused by name, not half read.
constexpr std::uint64_t kCheckpointFormat = 2;

/// Silences HDF5's own error printing once: failures become exceptions with a message of ours.
void quiet_hdf5() {
  static const bool done = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return true;
  }();
  (void)done;
}

/// An HDF5 identifier closed on scope exit.
class Handle {
 public:
  using Close = herr_t (*)(hid_t);
  Handle(hid_t id, Close close, const std::string& what) : id_(id), close_(close) {
    if (id_ < 0) throw std::runtime_error("HDF5: cannot " + what);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() {
    if (id_ >= 0) close_(id_);
  }
  operator hid_t() const { return id_; }  // NOLINT: used as the id it wraps

 private:
  hid_t id_;
  Close close_;
};

void check(herr_t status, const std::string& what) {
  if (status < 0) throw std::runtime_error("HDF5: cannot " + what);
}

/// Per value type: the HDF5 memory type, the scalar element and components per particle.
template <class T>
struct H5Traits;
template <>
struct H5Traits<double> {
  static hid_t type() { return H5T_NATIVE_DOUBLE; }
  static constexpr int components = 1;
  static FieldLayout layout(std::string n) { return {std::move(n), "Float", 8, 1}; }
};
template <int D, int O, int R, int C>
struct H5Traits<Eigen::Matrix<double, D, 1, O, R, C>> {
  static hid_t type() { return H5T_NATIVE_DOUBLE; }
  static constexpr int components = D;
  static FieldLayout layout(std::string n) { return {std::move(n), "Float", 8, D}; }
};
template <>
struct H5Traits<std::int32_t> {
  static hid_t type() { return H5T_NATIVE_INT32; }
  static constexpr int components = 1;
  static FieldLayout layout(std::string n) { return {std::move(n), "Int", 4, 1}; }
};
template <class E>
struct ByteEnumTraits {
  static_assert(sizeof(E) == 1);
  static hid_t type() { return H5T_NATIVE_UINT8; }
  static constexpr int components = 1;
  static FieldLayout layout(std::string n) { return {std::move(n), "UChar", 1, 1}; }
};
template <>
struct H5Traits<Kind> : ByteEnumTraits<Kind> {};
template <>
struct H5Traits<Origin> : ByteEnumTraits<Origin> {};
template <>
struct H5Traits<Role> : ByteEnumTraits<Role> {};
template <>
struct H5Traits<std::uint64_t> {
  static hid_t type() { return H5T_NATIVE_UINT64; }
  static constexpr int components = 1;
  static FieldLayout layout(std::string n) { return {std::move(n), "UInt", 8, 1}; }
};

template <class T>
void write_attribute(hid_t object, const char* name, hid_t type, const T& value) {
  const Handle space(H5Screate(H5S_SCALAR), H5Sclose, "create a dataspace");
  const Handle attr(H5Acreate2(object, name, type, space, kDefault, kDefault), H5Aclose,
                    std::string("create attribute ") + name);
  check(H5Awrite(attr, type, &value), std::string("write attribute ") + name);
}

void write_double_array_attribute(hid_t object, const char* name, const std::vector<double>& values) {
  const hsize_t count = values.size();
  const Handle space(count == 0 ? H5Screate(H5S_NULL) : H5Screate_simple(1, &count, nullptr), H5Sclose,
                     "create a dataspace");
  const Handle attr(H5Acreate2(object, name, H5T_NATIVE_DOUBLE, space, kDefault, kDefault), H5Aclose,
                    std::string("create attribute ") + name);
  if (count > 0) check(H5Awrite(attr, H5T_NATIVE_DOUBLE, values.data()), std::string("write attribute ") + name);
}

std::vector<double> read_double_array_attribute(hid_t object, const char* name) {
  const Handle attr(H5Aopen(object, name, kDefault), H5Aclose, std::string("open attribute ") + name);
  const Handle space(H5Aget_space(attr), H5Sclose, std::string("get the dataspace of attribute ") + name);
  const hssize_t count = H5Sget_simple_extent_npoints(space);
  if (count < 0) throw std::runtime_error(std::string("HDF5: cannot size attribute ") + name);
  std::vector<double> values(static_cast<std::size_t>(count));
  if (count > 0) check(H5Aread(attr, H5T_NATIVE_DOUBLE, values.data()), std::string("read attribute ") + name);
  return values;
}

void write_string_attribute(hid_t object, const char* name, const std::string& value) {
  const Handle type(H5Tcopy(H5T_C_S1), H5Tclose, "copy the string type");
  check(H5Tset_size(type, std::max<std::size_t>(1, value.size())), "size a string type");
  const Handle space(H5Screate(H5S_SCALAR), H5Sclose, "create a dataspace");
  const Handle attr(H5Acreate2(object, name, type, space, kDefault, kDefault), H5Aclose,
                    std::string("create attribute ") + name);
  std::string padded = value;
  if (padded.empty()) padded.push_back('\0');
  check(H5Awrite(attr, type, padded.data()), std::string("write attribute ") + name);
}

template <class T>
T read_attribute(hid_t object, const char* name, hid_t type) {
  const Handle attr(H5Aopen(object, name, kDefault), H5Aclose, std::string("open attribute ") + name);
  T value{};
  check(H5Aread(attr, type, &value), std::string("read attribute ") + name);
  return value;
}

std::string read_string_attribute(hid_t object, const char* name) {
  const Handle attr(H5Aopen(object, name, kDefault), H5Aclose, std::string("open attribute ") + name);
  const Handle type(H5Aget_type(attr), H5Tclose, "get an attribute type");
  const std::size_t size = H5Tget_size(type);
  std::string value(size, '\0');
  const Handle mem(H5Tcopy(H5T_C_S1), H5Tclose, "copy the string type");
  check(H5Tset_size(mem, size), "size a string type");
  check(H5Aread(attr, mem, value.data()), std::string("read attribute ") + name);
  while (!value.empty() && value.back() == '\0') value.pop_back();
  return value;
}

bool has_attribute(hid_t object, const char* name) { return H5Aexists(object, name) > 0; }

/// Which rows of a file this process writes: in one process all of them; across ranks (parallel HDF5), rows
/// [offset, offset + its count) of `total`, every rank writing its rows of each dataset at once (collectively).
struct Part {
  hsize_t total = 0;
  hsize_t offset = 0;
  hid_t fapl = kDefault;  // file access: the MPI-IO driver across ranks
  hid_t dxpl = kDefault;  // transfer: collective across ranks
  bool shared = false;
};

/// One field as a dataset named after it, with its unit as the dataset's `units` attribute: this process's rows.
template <class T>
void write_dataset(hid_t group, const Field<T>& field, const std::vector<T>& values, const Part& part) {
  using Tr = H5Traits<T>;
  const std::string name(field.name());
  const int rank = Tr::components > 1 ? 2 : 1;
  const hsize_t dims[2] = {part.shared ? part.total : values.size(), static_cast<hsize_t>(Tr::components)};
  const Handle space(H5Screate_simple(rank, dims, nullptr), H5Sclose, "create a dataspace");
  const Handle set(H5Dcreate2(group, name.c_str(), Tr::type(), space, kDefault, kDefault, kDefault), H5Dclose,
                   "create dataset " + name);
  if (!part.shared) {
    if (!values.empty()) check(H5Dwrite(set, Tr::type(), H5S_ALL, H5S_ALL, kDefault, values.data()), "write dataset " + name);
  } else {  // every rank takes part, also with no rows of its own
    const hsize_t start[2] = {part.offset, 0}, count[2] = {values.size(), static_cast<hsize_t>(Tr::components)};
    const Handle file_space(H5Dget_space(set), H5Sclose, "get the dataspace of " + name);
    const Handle memory(H5Screate_simple(rank, count, nullptr), H5Sclose, "create a dataspace");
    if (values.empty()) {
      check(H5Sselect_none(file_space), "select no rows of " + name);
      check(H5Sselect_none(memory), "select no rows");
    } else {
      check(H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, nullptr, count, nullptr), "select rows of " + name);
    }
    check(H5Dwrite(set, Tr::type(), memory, file_space, part.dxpl, values.empty() ? nullptr : values.data()),
          "write dataset " + name);
  }
  write_string_attribute(set, "units", std::string(field.unit()));
}

/// The Part of a file of `count` rows from this process: with `comm` across ranks (parallel HDF5), its rows after
/// the lower ranks' and the MPI-IO property lists, which it owns. Collective.
class PartLists {
 public:
  PartLists(std::size_t count, const par::Comm* comm) {
    part.total = count;
    if (comm == nullptr || !comm->distributed()) return;
#ifdef H5_HAVE_PARALLEL
    std::uint64_t below = 0, total = 0;
    const auto counts = comm->all_gather_value(static_cast<std::uint64_t>(count));
    for (std::size_t r = 0; r < counts.size(); ++r) {
      if (static_cast<int>(r) < comm->rank()) below += counts[r];
      total += counts[r];
    }
    part.total = total;
    part.offset = below;
    part.shared = true;
    fapl_.emplace(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "create file access properties");
    check(H5Pset_fapl_mpio(*fapl_, static_cast<MPI_Comm>(comm->native()), MPI_INFO_NULL), "set the MPI-IO driver");
    dxpl_.emplace(H5Pcreate(H5P_DATASET_XFER), H5Pclose, "create transfer properties");
    check(H5Pset_dxpl_mpio(*dxpl_, H5FD_MPIO_COLLECTIVE), "set collective transfers");
    part.fapl = *fapl_;
    part.dxpl = *dxpl_;
#else
    throw std::logic_error("HDF5: a file written across ranks needs parallel HDF5 (the mpi preset links it)");
#endif
  }
  Part part;

 private:
  std::optional<Handle> fapl_, dxpl_;
};

/// After every rank closed the file: the root renames it into place, and the others wait for that.
void commit_part(const std::filesystem::path& file, const par::Comm* comm) {
  if (comm == nullptr || !comm->distributed()) {
    commit_file(file);
    return;
  }
  comm->barrier();
  if (comm->root()) commit_file(file);
  comm->barrier();
}

/// Rows [first, last) of a dataset that must hold `total` rows.
struct Rows {
  hsize_t first = 0, last = 0, total = 0;
};

template <class T>
void read_dataset(hid_t group, const std::string& name, std::vector<T>& values, std::optional<Rows> rows = std::nullopt) {
  using Tr = H5Traits<T>;
  const Handle set(H5Dopen2(group, name.c_str(), kDefault), H5Dclose, "open dataset " + name);
  const Handle space(H5Dget_space(set), H5Sclose, "get the dataspace of " + name);
  const int rank = H5Sget_simple_extent_ndims(space);
  hsize_t dims[2] = {0, 1};
  if (rank < 1 || rank > 2 || H5Sget_simple_extent_dims(space, dims, nullptr) < 0) {
    throw std::runtime_error("HDF5: dataset " + name + " has an unexpected shape");
  }
  if (static_cast<int>(rank == 2 ? dims[1] : 1) != Tr::components) {
    throw std::runtime_error("HDF5: dataset " + name + " has the wrong number of components");
  }
  if (!rows) {
    values.resize(dims[0], zero_value<T>());
    if (!values.empty()) check(H5Dread(set, Tr::type(), H5S_ALL, H5S_ALL, kDefault, values.data()), "read dataset " + name);
    return;
  }
  // Rows [first, last) only: a hyperslab of the file's dataspace into a memory space of that many rows.
  if (dims[0] != rows->total) throw std::runtime_error("HDF5: dataset " + name + " has the wrong size");
  const hsize_t first = rows->first, last = rows->last;
  values.resize(last - first, zero_value<T>());
  if (values.empty()) return;
  const hsize_t start[2] = {first, 0}, count[2] = {last - first, dims[1]};
  check(H5Sselect_hyperslab(space, H5S_SELECT_SET, start, nullptr, count, nullptr), "select rows of " + name);
  const Handle memory(H5Screate_simple(rank, count, nullptr), H5Sclose, "a memory dataspace for " + name);
  check(H5Dread(set, Tr::type(), memory, space, kDefault, values.data()), "read rows of dataset " + name);
}

/// The particles a file holds (fluid and walls: not ghosts, not halos), in id order: the order is the particles'
/// own, not the store's, so a frame is the same file at any thread count and any rank count (issue #19).
template <int D>
std::vector<std::size_t> non_ghosts(const ParticleStore<D>& store) {
  std::vector<std::size_t> keep;
  keep.reserve(store.size());
  for (std::size_t i = 0; i < store.size(); ++i) {
    if (store.kind[i] == Kind::fluid || store.kind[i] == Kind::wall) keep.push_back(i);
  }
  std::sort(keep.begin(), keep.end(), [&](std::size_t a, std::size_t b) { return store.id[a] < store.id[b]; });
  return keep;
}

template <class T>
std::vector<T> gathered(const Field<T>& f, const std::vector<std::size_t>& keep) {
  std::vector<T> out(keep.size(), zero_value<T>());
  for (std::size_t k = 0; k < keep.size(); ++k) out[k] = f[keep[k]];
  return out;
}

bool wanted(const std::vector<std::string>& fields, std::string_view name) {
  return fields.empty() || name == "position" || std::find(fields.begin(), fields.end(), name) != fields.end();
}

}  // namespace

namespace {

template <int D>
std::vector<FieldLayout> layouts_in() {
  std::vector<FieldLayout> out;
  const ParticleStore<D> store;
  store.for_each_field([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::value_type;
    out.push_back(H5Traits<T>::layout(std::string(f.name())));
  });
  return out;
}

/// The dimension of a frame or checkpoint group: the second extent of its position dataset.
int group_dimension(hid_t group) {
  const Handle set(H5Dopen2(group, "position", kDefault), H5Dclose, "open dataset position");
  const Handle space(H5Dget_space(set), H5Sclose, "get the dataspace of position");
  hsize_t dims[2] = {0, 0};
  if (H5Sget_simple_extent_ndims(space) != 2 || H5Sget_simple_extent_dims(space, dims, nullptr) < 0 ||
      (dims[1] != 2 && dims[1] != 3)) {
    throw std::runtime_error("HDF5: dataset position is not N x 2 or N x 3");
  }
  return static_cast<int>(dims[1]);
}

}  // namespace

std::vector<FieldLayout> field_layouts(int dimension) { return dimension == 3 ? layouts_in<3>() : layouts_in<2>(); }

namespace {

/// Calls write(particles, comm) with the particles this process writes: the store in one process; across ranks,
/// this rank's run of ids (share_in_id_order), so that the file is the one a single process writes. Collective.
template <int D, class Write>
auto with_rows_in_id_order(const ParticleStore<D>& store, const par::Comm* comm, Write&& write) {
  if (comm != nullptr && comm->distributed()) return write(share_in_id_order(store, *comm), comm);
  return write(store, nullptr);
}

/// A frame of the store's fluid and walls in id order: with `comm`, this rank's rows of it (its run of ids).
template <int D>
FrameHeader write_frame_rows(const std::filesystem::path& file, const std::string& group, const ParticleStore<D>& store,
                             double time, std::uint64_t step, std::uint64_t index,
                             const std::vector<std::string>& fields, const par::Comm* comm) {
  const std::vector<std::size_t> keep = non_ghosts(store);
  const PartLists lists(keep.size(), comm);
  const Part& part = lists.part;
  FrameHeader header{group, time, step, index, part.total, {}};
  const std::filesystem::path tmp = temporary_path(file);
  {
    const Handle f(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, kDefault, part.fapl), H5Fclose, "create " + tmp.string());
    const Handle g(H5Gcreate2(f, group.c_str(), kDefault, kDefault, kDefault), H5Gclose, "create group " + group);
    write_attribute(g, "time", H5T_NATIVE_DOUBLE, time);
    write_string_attribute(g, "time_units", "s");  // step, frame and particles are counts
    write_attribute(g, "step", H5T_NATIVE_UINT64, step);
    write_attribute(g, "frame", H5T_NATIVE_UINT64, index);
    write_attribute(g, "particles", H5T_NATIVE_UINT64, header.particles);
    store.for_each_field([&](const auto& field) {
      if (!wanted(fields, field.name())) return;
      using T = typename std::decay_t<decltype(field)>::value_type;
      write_dataset(g, field, gathered(field, keep), part);
      header.fields.push_back(H5Traits<T>::layout(std::string(field.name())));
    });
  }
  commit_part(file, comm);
  return header;
}

}  // namespace

template <int D>
FrameHeader write_frame(const std::filesystem::path& file, const std::string& group, const ParticleStore<D>& store,
                        double time, std::uint64_t step, std::uint64_t index, const std::vector<std::string>& fields,
                        const par::Comm* comm) {
  quiet_hdf5();
  return with_rows_in_id_order(store, comm, [&](const ParticleStore<D>& rows, const par::Comm* c) {
    return write_frame_rows(file, group, rows, time, step, index, fields, c);
  });
}

FrameHeader read_frame_header(const std::filesystem::path& file, const std::string& group) {
  quiet_hdf5();
  const Handle f(H5Fopen(file.c_str(), H5F_ACC_RDONLY, kDefault), H5Fclose, "open " + file.string());
  const Handle g(H5Gopen2(f, group.c_str(), kDefault), H5Gclose, "open group " + group + " in " + file.string());
  FrameHeader h;
  h.group = group;
  h.time = read_attribute<double>(g, "time", H5T_NATIVE_DOUBLE);
  h.step = read_attribute<std::uint64_t>(g, "step", H5T_NATIVE_UINT64);
  h.index = read_attribute<std::uint64_t>(g, "frame", H5T_NATIVE_UINT64);
  h.particles = read_attribute<std::uint64_t>(g, "particles", H5T_NATIVE_UINT64);
  for (const FieldLayout& layout : field_layouts(group_dimension(g))) {
    if (H5Lexists(g, layout.name.c_str(), kDefault) > 0) h.fields.push_back(layout);
  }
  return h;
}

std::vector<double> read_frame_field(const std::filesystem::path& file, const std::string& group, const std::string& field) {
  quiet_hdf5();
  const Handle f(H5Fopen(file.c_str(), H5F_ACC_RDONLY, kDefault), H5Fclose, "open " + file.string());
  const Handle g(H5Gopen2(f, group.c_str(), kDefault), H5Gclose, "open group " + group);
  const Handle set(H5Dopen2(g, field.c_str(), kDefault), H5Dclose, "open dataset " + field);
  const Handle space(H5Dget_space(set), H5Sclose, "get the dataspace of " + field);
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  if (n < 0) throw std::runtime_error("HDF5: cannot size dataset " + field);
  std::vector<double> values(static_cast<std::size_t>(n));
  if (n > 0) check(H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, kDefault, values.data()), "read dataset " + field);
  return values;
}

namespace {

template <int D>
void write_checkpoint_rows(const std::filesystem::path& file, const ParticleStore<D>& store, const CheckpointState& state,
                           const par::Comm* comm) {
  const std::vector<std::size_t> keep = non_ghosts(store);
  const PartLists lists(keep.size(), comm);
  const Part& part = lists.part;
  const std::filesystem::path tmp = temporary_path(file);
  {
    const Handle f(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, kDefault, part.fapl), H5Fclose, "create " + tmp.string());
    const Handle g(H5Gcreate2(f, kCheckpointGroup, kDefault, kDefault, kDefault), H5Gclose, "create the checkpoint group");
    write_attribute(g, "format", H5T_NATIVE_UINT64, kCheckpointFormat);
    write_attribute(g, "time", H5T_NATIVE_DOUBLE, state.time);
    write_attribute(g, "step", H5T_NATIVE_UINT64, state.step);
    write_attribute(g, "dt", H5T_NATIVE_DOUBLE, state.dt);
    write_string_attribute(g, "time_units", "s");  // of time and dt
    write_attribute(g, "next_id", H5T_NATIVE_UINT64, state.next_id);
    write_attribute(g, "next_row", H5T_NATIVE_UINT64, state.next_row);
    write_attribute(g, "next_frame", H5T_NATIVE_UINT64, state.next_frame);
    write_attribute(g, "frame_count", H5T_NATIVE_UINT64, state.frame_count);
    write_attribute(g, "next_checkpoint", H5T_NATIVE_UINT64, state.next_checkpoint);
    write_attribute(g, "particle_steps", H5T_NATIVE_UINT64, state.particle_steps);
    write_attribute(g, "fine_steps", H5T_NATIVE_UINT64, state.fine_steps);
    write_attribute(g, "initial_mass", H5T_NATIVE_DOUBLE, state.initial_mass);
    write_attribute(g, "initial_momentum_x", H5T_NATIVE_DOUBLE, state.initial_momentum_x);
    write_attribute(g, "initial_momentum_y", H5T_NATIVE_DOUBLE, state.initial_momentum_y);
    if (D == 3) write_attribute(g, "initial_momentum_z", H5T_NATIVE_DOUBLE, state.initial_momentum_z);
    write_attribute(g, "dimension", H5T_NATIVE_UINT64, static_cast<std::uint64_t>(D));
    write_attribute(g, "removed_particles", H5T_NATIVE_UINT64, state.removed_particles);
    write_double_array_attribute(g, "removed_mass_parts", state.removed_mass_parts);
    write_attribute(g, "particles", H5T_NATIVE_UINT64, static_cast<std::uint64_t>(part.total));
    write_string_attribute(g, "scene", state.scene);
    store.for_each_field([&](const auto& field) { write_dataset(g, field, gathered(field, keep), part); });
  }
  commit_part(file, comm);
}

}  // namespace

template <int D>
void write_checkpoint(const std::filesystem::path& file, const ParticleStore<D>& store, const CheckpointState& state,
                      const par::Comm* comm) {
  quiet_hdf5();
  with_rows_in_id_order(store, comm, [&](const ParticleStore<D>& rows, const par::Comm* c) {
    write_checkpoint_rows(file, rows, state, c);
  });
}

std::string checkpoint_problem(const std::filesystem::path& file) {
  quiet_hdf5();
  const hid_t id = H5Fopen(file.c_str(), H5F_ACC_RDONLY, kDefault);
  if (id < 0) return "not an HDF5 file";
  const Handle f(id, H5Fclose, "open " + file.string());
  if (H5Lexists(f, kCheckpointGroup, kDefault) <= 0) return std::string("an HDF5 file without the '") + kCheckpointGroup + "' group";
  const Handle g(H5Gopen2(f, kCheckpointGroup, kDefault), H5Gclose, "open the checkpoint group of " + file.string());
  if (!has_attribute(g, "format")) return "its checkpoint group has no format attribute";
  const auto format = read_attribute<std::uint64_t>(g, "format", H5T_NATIVE_UINT64);
  if (format != kCheckpointFormat) {
    return "checkpoint format " + std::to_string(format) + "; this program reads format " + std::to_string(kCheckpointFormat);
  }
  return "";
}

int checkpoint_dimension(const std::filesystem::path& file) {
  if (const std::string why = checkpoint_problem(file); !why.empty()) {
    throw std::runtime_error(file.string() + " is not a sphrefine checkpoint (" + why + ")");
  }
  const Handle f(H5Fopen(file.c_str(), H5F_ACC_RDONLY, kDefault), H5Fclose, "open " + file.string());
  const Handle g(H5Gopen2(f, kCheckpointGroup, kDefault), H5Gclose, "open the checkpoint group of " + file.string());
  // Absent from checkpoints written before 3D: those are 2D.
  return has_attribute(g, "dimension") ? static_cast<int>(read_attribute<std::uint64_t>(g, "dimension", H5T_NATIVE_UINT64)) : 2;
}

template <int D>
CheckpointState read_checkpoint(const std::filesystem::path& file, ParticleStore<D>& store, const par::Comm* comm) {
  if (const int dim = checkpoint_dimension(file); dim != D) {
    throw std::runtime_error(file.string() + " is a " + std::to_string(dim) + "D checkpoint; this run is " +
                             std::to_string(D) + "D");
  }
  const Handle f(H5Fopen(file.c_str(), H5F_ACC_RDONLY, kDefault), H5Fclose, "open " + file.string());
  const Handle g(H5Gopen2(f, kCheckpointGroup, kDefault), H5Gclose, "open the checkpoint group of " + file.string());
  CheckpointState s;
  s.time = read_attribute<double>(g, "time", H5T_NATIVE_DOUBLE);
  s.step = read_attribute<std::uint64_t>(g, "step", H5T_NATIVE_UINT64);
  s.dt = read_attribute<double>(g, "dt", H5T_NATIVE_DOUBLE);
  s.next_id = read_attribute<std::uint64_t>(g, "next_id", H5T_NATIVE_UINT64);
  s.next_row = read_attribute<std::uint64_t>(g, "next_row", H5T_NATIVE_UINT64);
  s.next_frame = read_attribute<std::uint64_t>(g, "next_frame", H5T_NATIVE_UINT64);
  s.frame_count = read_attribute<std::uint64_t>(g, "frame_count", H5T_NATIVE_UINT64);
  s.next_checkpoint = read_attribute<std::uint64_t>(g, "next_checkpoint", H5T_NATIVE_UINT64);
  s.particle_steps = read_attribute<std::uint64_t>(g, "particle_steps", H5T_NATIVE_UINT64);
  // Absent from checkpoints written before per-level steps: every step was one step of the finest bin then.
  s.fine_steps = has_attribute(g, "fine_steps") ? read_attribute<std::uint64_t>(g, "fine_steps", H5T_NATIVE_UINT64) : s.step;
  s.initial_mass = read_attribute<double>(g, "initial_mass", H5T_NATIVE_DOUBLE);
  s.initial_momentum_x = read_attribute<double>(g, "initial_momentum_x", H5T_NATIVE_DOUBLE);
  s.initial_momentum_y = read_attribute<double>(g, "initial_momentum_y", H5T_NATIVE_DOUBLE);
  if (D == 3) s.initial_momentum_z = read_attribute<double>(g, "initial_momentum_z", H5T_NATIVE_DOUBLE);
  // Absent from checkpoints written before outflow removal existed: nothing was removed then.
  if (has_attribute(g, "removed_particles")) {
    s.removed_particles = read_attribute<std::uint64_t>(g, "removed_particles", H5T_NATIVE_UINT64);
    if (has_attribute(g, "removed_mass_parts")) {
      s.removed_mass_parts = read_double_array_attribute(g, "removed_mass_parts");
    } else {  // written with a compensated sum (before the exact one): its value and compensation, summed exactly
      s.removed_mass_parts = {read_attribute<double>(g, "removed_mass", H5T_NATIVE_DOUBLE),
                              read_attribute<double>(g, "removed_mass_compensation", H5T_NATIVE_DOUBLE)};
    }
  }
  s.scene = read_string_attribute(g, "scene");
  const auto n = read_attribute<std::uint64_t>(g, "particles", H5T_NATIVE_UINT64);
  store.clear();
  // This process's rows: all of them, or across ranks this rank's slab.
  const bool shared = comm != nullptr && comm->distributed();
  const auto r = shared ? static_cast<hsize_t>(comm->rank()) : 0, p = shared ? static_cast<hsize_t>(comm->size()) : 1;
  const Rows rows{n * r / p, n * (r + 1) / p, n};
  try {
    store.for_each_field([&](auto& field) { read_dataset(g, std::string(field.name()), field.values(), rows); });
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(file.string() + ": " + e.what());
  }
  if (shared) {  // every slab's wall particles on every rank (in rank order, which is id order)
    std::vector<std::byte> walls;
    for (std::size_t i = 0; i < store.size(); ++i)
      if (store.kind[i] == Kind::wall) pack_particle(store, i, walls);
    store.compact([&](std::size_t i) { return store.kind[i] != Kind::wall; });
    unpack_particles(store, comm->all_gather(walls));
  }
  store.set_next_id(s.next_id);
  return s;
}

template FrameHeader write_frame<2>(const std::filesystem::path&, const std::string&, const ParticleStore<2>&, double,
                                    std::uint64_t, std::uint64_t, const std::vector<std::string>&, const par::Comm*);
template FrameHeader write_frame<3>(const std::filesystem::path&, const std::string&, const ParticleStore<3>&, double,
                                    std::uint64_t, std::uint64_t, const std::vector<std::string>&, const par::Comm*);
template void write_checkpoint<2>(const std::filesystem::path&, const ParticleStore<2>&, const CheckpointState&,
                                  const par::Comm*);
template void write_checkpoint<3>(const std::filesystem::path&, const ParticleStore<3>&, const CheckpointState&,
                                  const par::Comm*);
template CheckpointState read_checkpoint<2>(const std::filesystem::path&, ParticleStore<2>&, const par::Comm*);
template CheckpointState read_checkpoint<3>(const std::filesystem::path&, ParticleStore<3>&, const par::Comm*);

}  // namespace sph::io
