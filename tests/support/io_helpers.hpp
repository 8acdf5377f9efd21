#pragma once
// Helpers shared by the set-up and I/O tests: one OpenMP thread (these tests check I/O, not threading; the
// determinism tests run 1 and N threads), a temporary folder, and a byte-for-byte store comparison.
#include <gtest/gtest.h>
#include <omp.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "core/particle_store.hpp"

namespace sph::test {

namespace fs = std::filesystem;

/// These tests check set-up and I/O, not threading (the determinism tests run 1 and N threads): one thread
/// keeps them fast when the machine is shared.
class OneThread : public ::testing::Environment {
 public:
  void SetUp() override { omp_set_num_threads(1); }
};
[[maybe_unused]] inline ::testing::Environment* const kOneThread =
    ::testing::AddGlobalTestEnvironment(new OneThread);

/// A fresh empty folder under the system temp directory, removed at the end of the test.
class TempFolder {
 public:
  TempFolder() {
    path_ = fs::temp_directory_path() / ("sph_test_io_" + std::to_string(::getpid()) + "_" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempFolder() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

template <int D>
void expect_bitwise_equal(const ParticleStore<D>& a, const ParticleStore<D>& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.next_id(), b.next_id());
  std::vector<std::vector<unsigned char>> fa, fb;
  auto collect = [](std::vector<std::vector<unsigned char>>& out) {
    return [&out](const auto& f) {
      const auto* p = reinterpret_cast<const unsigned char*>(f.data());
      out.emplace_back(p, p + f.size() * sizeof(*f.data()));
    };
  };
  a.for_each_field(collect(fa));
  b.for_each_field(collect(fb));
  std::vector<std::string> names;
  a.for_each_field([&](const auto& f) { names.emplace_back(f.name()); });
  for (std::size_t k = 0; k < fa.size(); ++k) EXPECT_TRUE(fa[k] == fb[k]) << "field " << names[k] << " differs";
}

}  // namespace sph::test
