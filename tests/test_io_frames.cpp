// HDF5 frames, the XDMF index and checkpoints: every field read back as written (ghosts left out), the
// XDMF's dataset paths and shapes match the HDF5 files, checkpoints restore the store exactly, and writes
// leave no temporary file behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <hdf5.h>
#include <omp.h>

#include <filesystem>
#include <map>
#include <regex>
#include <string>
#include <tuple>
#include <unistd.h>

#include "core/case_builder.hpp"
#include "core/io/atomic_file.hpp"
#include "core/io/hdf5_frames.hpp"
#include "core/io/output_folder.hpp"
#include "core/io/xdmf.hpp"
#include "core/scene/scene_parser.hpp"

#include "tests/support/io_helpers.hpp"

namespace {

using namespace sph;
using test::TempFolder;
using test::expect_bitwise_equal;
namespace fs = std::filesystem;



/// A dam break a few steps in: fluid, wall and ghost particles, several levels of nothing special.
Simulation small_dam() {
  DamBreakSpec spec;
  spec.column_width = 5.0;
  spec.column_height = 5.0;
  spec.tank_width = 10.0;
  spec.tank_height = 10.0;
  spec.spacing = 0.5;
  Simulation sim = make_dam_break(spec);
  for (int k = 0; k < 5; ++k) sim.step();
  return sim;
}

/// The particles a file holds, in its order: fluid and wall particles (no ghosts, no halos), by id.
std::vector<std::size_t> non_ghosts(const ParticleStore<2>& s) {
  std::vector<std::size_t> keep;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] == Kind::fluid || s.kind[i] == Kind::wall) keep.push_back(i);
  }
  std::sort(keep.begin(), keep.end(), [&](std::size_t a, std::size_t b) { return s.id[a] < s.id[b]; });
  return keep;
}

/// A field as doubles, in the order HDF5 stores it.
template <class T>
std::vector<double> as_doubles(const Field<T>& f, const std::vector<std::size_t>& keep) {
  std::vector<double> out;
  for (std::size_t i : keep) {
    if constexpr (std::is_same_v<T, Vec<2>>) {
      out.push_back(f[i][0]);
      out.push_back(f[i][1]);
    } else {
      out.push_back(static_cast<double>(f[i]));
    }
  }
  return out;
}

TEST(IoFrames, EveryFieldReadsBackAsWrittenWithoutGhosts) {
  TempFolder tmp;
  const Simulation sim = small_dam();
  const ParticleStore<2>& s = sim.store();
  ASSERT_GT(sim.diagnostics().ghosts, 0u);
  const fs::path file = tmp.path() / "frame.h5";
  const io::FrameHeader h = io::write_frame(file, "frame_000003", s, sim.time(), sim.step_count(), 3, {});
  EXPECT_FALSE(fs::exists(io::temporary_path(file)));

  const auto keep = non_ghosts(s);
  EXPECT_EQ(h.particles, keep.size());
  const io::FrameHeader r = io::read_frame_header(file, "frame_000003");
  EXPECT_EQ(r.time, sim.time());
  EXPECT_EQ(r.step, sim.step_count());
  EXPECT_EQ(r.index, 3u);
  EXPECT_EQ(r.particles, keep.size());
  EXPECT_EQ(r.fields, io::field_layouts());
  // Every field of the store's registry reads back (a field the writer left out fails to read).
  s.for_each_field([&](const auto& f) {
    const std::string name(f.name());
    EXPECT_EQ(io::read_frame_field(file, "frame_000003", name), as_doubles(f, keep)) << name;
  });
}

/// A string attribute of an HDF5 object ("<none>" when absent), read with the HDF5 API directly.
std::string string_attribute(hid_t object, const char* name) {
  if (H5Aexists(object, name) <= 0) return "<none>";
  const hid_t attr = H5Aopen(object, name, H5P_DEFAULT);
  const hid_t type = H5Aget_type(attr);
  std::string value(H5Tget_size(type), '\0');
  const hid_t mem = H5Tcopy(H5T_C_S1);
  H5Tset_size(mem, value.size());
  if (H5Aread(attr, mem, value.data()) < 0) value = "<unreadable>";
  H5Tclose(mem);
  H5Tclose(type);
  H5Aclose(attr);
  while (!value.empty() && value.back() == '\0') value.pop_back();
  return value;
}

/// Every dataset of a group (whatever its name: not only the fields the writer knows) with its units attribute.
std::map<std::string, std::string> units_of_every_dataset(const fs::path& file, const std::string& group,
                                                          std::string* time_units) {
  std::map<std::string, std::string> out;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t g = H5Gopen2(f, group.c_str(), H5P_DEFAULT);
  H5G_info_t info;
  H5Gget_info(g, &info);
  for (hsize_t k = 0; k < info.nlinks; ++k) {
    char name[256];
    H5Lget_name_by_idx(g, ".", H5_INDEX_NAME, H5_ITER_INC, k, name, sizeof name, H5P_DEFAULT);
    const hid_t set = H5Dopen2(g, name, H5P_DEFAULT);
    out[name] = string_attribute(set, "units");
    H5Dclose(set);
  }
  *time_units = string_attribute(g, "time_units");
  H5Gclose(g);
  H5Fclose(f);
  return out;
}

TEST(IoFrames, EveryDatasetCarriesItsUnits) {
  TempFolder tmp;
  Simulation sim = small_dam();
  const std::map<std::string, std::string> expected{
      {"position", "m"},       {"velocity", "m/s"},         {"density", "kg/m^3"},    {"pressure", "Pa"},
      {"mass", "kg/m"},        {"smoothing_length", "m"},   {"spacing", "m"},         {"level", "1"},
      {"kind", "1"},           {"id", "1"},                 {"density_rate", "kg/m^3/s"},
      {"acceleration", "m/s^2"}, {"velocity_half", "m/s"}, {"density_half", "kg/m^3"}, {"level_time", "s"},
      {"origin", "1"},         {"kick_rate", "m/s^2"},      {"kick_density_rate", "kg/m^3/s"},
      {"time_bin", "1"}, {"time_step_limit", "s"},       {"next_time_bin", "1"},      {"acoustic_stiffness", "1"},
      {"jerk", "m/s^3"}, {"density_jerk", "kg/m^3/s^2"}, {"role", "1"}, {"tie_offset", "m"},
      {"acceleration_all_pairs", "m/s^2"}, {"density_rate_all_pairs", "kg/m^3/s"}, {"velocity_at_step_start", "m/s"},
      {"density_at_step_start", "kg/m^3"}};
  std::string time_units;
  const fs::path frame = tmp.path() / "frame.h5";
  (void)io::write_frame(frame, "frame_000000", sim.store(), sim.time(), sim.step_count(), 0, {});
  EXPECT_EQ(units_of_every_dataset(frame, "frame_000000", &time_units), expected);
  EXPECT_EQ(time_units, "s");
  // A frame of a few fields: the same units for those.
  (void)io::write_frame(frame, "g", sim.store(), 0.0, 0, 0, {"pressure", "level"});
  EXPECT_EQ(units_of_every_dataset(frame, "g", &time_units),
            (std::map<std::string, std::string>{{"position", "m"}, {"pressure", "Pa"}, {"level", "1"}}));
  // Checkpoints too.
  io::CheckpointState state;
  state.scene = "{}";
  (void)io::write_checkpoint(tmp.path() / "checkpoint.h5", sim.store(), state);
  EXPECT_EQ(units_of_every_dataset(tmp.path() / "checkpoint.h5", "checkpoint", &time_units), expected);
  EXPECT_EQ(time_units, "s");
}

TEST(IoFrames, SelectedFieldsAlwaysIncludePosition) {
  TempFolder tmp;
  const Simulation sim = small_dam();
  const fs::path file = tmp.path() / "frame.h5";
  const io::FrameHeader h = io::write_frame(file, "g", sim.store(), 0.0, 0, 0, {"density", "level"});
  ASSERT_EQ(h.fields.size(), 3u);
  EXPECT_EQ(h.fields[0].name, "position");
  EXPECT_EQ(io::read_frame_header(file, "g").fields.size(), 3u);
  EXPECT_THROW((void)io::read_frame_field(file, "g", "velocity"), std::runtime_error);
}

TEST(IoFrames, XdmfDatasetPathsAndShapesMatchTheHdf5Files) {
  TempFolder tmp;
  Simulation sim = small_dam();
  const io::RunFiles files{tmp.path()};
  fs::create_directories(files.frames());
  std::vector<io::XdmfEntry> entries;
  for (std::uint64_t k = 0; k < 3; ++k) {
    const io::FrameHeader h = io::write_frame(files.frame(k), io::RunFiles::frame_group(k), sim.store(), sim.time(),
                                              sim.step_count(), k, {});
    entries.push_back({"frames/" + io::RunFiles::frame_file_name(k), h});
    sim.step();
  }
  io::write_xdmf(files.xdmf(), entries);
  const std::string xml = io::read_file(files.xdmf());

  // One uniform grid per frame, in a temporal collection, each with its time.
  const std::regex grid(R"re(<Grid Name="(frame_\d{6})" GridType="Uniform">\s*<Time Value="([^"]+)"/>\s*<Topology TopologyType="Polyvertex" Dimensions="(\d+)"/>)re");
  int grids = 0;
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), grid); it != std::sregex_iterator(); ++it, ++grids) {
    EXPECT_EQ((*it)[1].str(), entries[static_cast<std::size_t>(grids)].frame.group);
    EXPECT_EQ(std::stod((*it)[2].str()), entries[static_cast<std::size_t>(grids)].frame.time);
    EXPECT_EQ(std::stoull((*it)[3].str()), entries[static_cast<std::size_t>(grids)].frame.particles);
  }
  EXPECT_EQ(grids, 3);
  EXPECT_NE(xml.find("CollectionType=\"Temporal\""), std::string::npos);
  EXPECT_NE(xml.find("<Geometry GeometryType=\"XY\">"), std::string::npos);

  // Every DataItem names an existing dataset whose size matches its Dimensions.
  const std::regex item(R"re(<DataItem Dimensions="(\d+)( (\d+))?" NumberType="(\w+)" Precision="(\d)" Format="HDF">([^:<]+):(/[^<]+)</DataItem>)re");
  int items = 0;
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), item); it != std::sregex_iterator(); ++it, ++items) {
    const std::size_t n = std::stoull((*it)[1].str());
    const std::size_t components = (*it)[3].matched ? std::stoull((*it)[3].str()) : 1;
    const fs::path file = tmp.path() / (*it)[6].str();
    const std::string dataset = (*it)[7].str();
    const std::size_t slash = dataset.rfind('/');
    ASSERT_TRUE(fs::exists(file)) << file;
    const auto values = io::read_frame_field(file, dataset.substr(1, slash - 1), dataset.substr(slash + 1));
    EXPECT_EQ(values.size(), n * components) << dataset;
  }
  EXPECT_EQ(items, 3 * std::tuple_size_v<decltype(ParticleStore<2>::field_members())>);  // every field of 3 frames
}

TEST(IoFrames, CheckpointRestoresEveryFieldAndTheNextId) {
  TempFolder tmp;
  Simulation sim = small_dam();
  sim.store().take_ids(17);  // a next id beyond the particles, as after refinement
  io::CheckpointState state;
  state.time = sim.time();
  state.step = sim.step_count();
  state.dt = sim.dt();
  state.next_id = sim.store().next_id();
  state.next_row = 4;
  state.next_frame = 2;
  state.frame_count = 2;
  state.scene = R"({"name": "x"})";
  const fs::path file = tmp.path() / "checkpoint.h5";
  io::write_checkpoint(file, sim.store(), state);

  ParticleStore<2> back;
  const io::CheckpointState r = io::read_checkpoint(file, back);
  EXPECT_EQ(r.time, state.time);
  EXPECT_EQ(r.step, state.step);
  EXPECT_EQ(r.dt, state.dt);
  EXPECT_EQ(r.next_row, 4u);
  EXPECT_EQ(r.frame_count, 2u);
  EXPECT_EQ(r.scene, state.scene);
  EXPECT_EQ(back.next_id(), sim.store().next_id());
  const auto keep = non_ghosts(sim.store());
  ASSERT_EQ(back.size(), keep.size());
  std::vector<std::vector<double>> a, b;
  sim.store().for_each_field([&](const auto& f) { a.push_back(as_doubles(f, keep)); });
  std::vector<std::size_t> all(back.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  back.for_each_field([&](const auto& f) { b.push_back(as_doubles(f, all)); });
  EXPECT_EQ(a, b);
}

TEST(IoFrames, ReadingAMissingOrForeignFileThrows) {
  TempFolder tmp;
  ParticleStore<2> s;
  EXPECT_THROW((void)io::read_checkpoint(tmp.path() / "nope.h5", s), std::runtime_error);
  io::write_file_atomic(tmp.path() / "text.h5", "not hdf5");
  EXPECT_THROW((void)io::read_checkpoint(tmp.path() / "text.h5", s), std::runtime_error);
  const Simulation sim = small_dam();
  (void)io::write_frame(tmp.path() / "frame.h5", "frame_000000", sim.store(), 0.0, 0, 0, {});
  EXPECT_THROW((void)io::read_checkpoint(tmp.path() / "frame.h5", s), std::runtime_error);
}

TEST(IoFrames, AtomicWriteReplacesWholeFiles) {
  TempFolder tmp;
  const fs::path f = tmp.path() / "a.txt";
  io::write_file_atomic(f, "first");
  io::write_file_atomic(f, "second");
  EXPECT_EQ(io::read_file(f), "second");
  EXPECT_FALSE(fs::exists(io::temporary_path(f)));
}

}  // namespace
