#pragma once
// The ranks of a run (issue #19): MPI's world when the program was started by mpirun in a build with MPI (the mpi
// preset, SPH_MPI), and otherwise one rank, the process itself, with every collective a no-op. The rest of the
// code calls only this: it compiles and runs the same without MPI.
//
// Every reduction here gives the same bits on every rank and at any rank count: minima, maxima and integer sums
// are exact, and a floating-point sum goes through par::ExactSum (each rank's parts are added exactly).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "parallel/exact_sum.hpp"

namespace sph::par {

class Comm {
 public:
  /// The run's ranks: MPI's world if MPI was started (par::Session), else one rank.
  static const Comm& world();

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool distributed() const { return size_ > 1; }
  bool root() const { return rank_ == 0; }

  double min(double x) const;
  double max(double x) const;
  std::uint64_t sum(std::uint64_t x) const;
  bool any(bool x) const;
  /// The exact sum over the ranks (each rank's parts added into one accumulator).
  ExactSum sum(const ExactSum& x) const;

  /// Sends out[r] to rank r (out has size() entries; out[rank()] comes back to this rank) and returns what every
  /// rank sent here, concatenated in rank order, with `from[r]` the bytes that came from rank r.
  std::vector<std::byte> exchange(const std::vector<std::vector<std::byte>>& out,
                                  std::vector<std::size_t>* from = nullptr) const;
  /// Every rank's bytes, concatenated in rank order, on every rank.
  std::vector<std::byte> all_gather(const std::vector<std::byte>& mine, std::vector<std::size_t>* from = nullptr) const;
  void barrier() const;

  /// A trivially copyable value from every rank, in rank order.
  template <class T>
  std::vector<T> all_gather_value(const T& mine) const {
    static_assert(std::is_trivially_copyable_v<T>);
    return all_gather_values(std::vector<T>{mine});
  }

  /// Every rank's values (plain data), concatenated in rank order, on every rank.
  template <class T>
  std::vector<T> all_gather_values(const std::vector<T>& mine) const {
    std::vector<std::byte> b(mine.size() * sizeof(T));
    if (!mine.empty()) std::memcpy(b.data(), static_cast<const void*>(mine.data()), b.size());
    const std::vector<std::byte> all = all_gather(b);
    std::vector<T> out(all.size() / sizeof(T));
    if (!out.empty()) std::memcpy(static_cast<void*>(out.data()), all.data(), all.size());
    return out;
  }

  /// The communicator (an MPI_Comm) of an MPI build; nullptr in one process.
  void* native() const { return native_; }

 private:
  friend class Session;
  int rank_ = 0;
  int size_ = 1;
  void* native_ = nullptr;
};

/// Starts MPI when this process was launched by an MPI launcher (mpirun sets OMPI_COMM_WORLD_SIZE, PMI_SIZE or
/// PMIX_RANK) in an MPI build, and finalises it at the end of the scope. Without a launcher the program runs as one
/// process and never touches MPI (no singleton start-up). A launcher with more than one rank in a build without MPI
/// is an error: every rank would run the whole scene and write the same files.
class Session {
 public:
  Session(int& argc, char**& argv);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  /// How many ranks the launcher asked for (1 without a launcher), read from its environment.
  static int launched_ranks();
  /// True in a build with MPI.
  static bool built_with_mpi();
  /// Ends every rank of the run with `code` (MPI_Abort); in one process, std::exit.
  [[noreturn]] static void abort(int code);

 private:
  bool started_ = false;
};

/// Appends a value to a byte buffer / reads one at `at` (advancing it): plain data, copied as its bytes (scalars,
/// enums, and Eigen's fixed-size vectors, which are plain arrays though not formally trivially copyable).
template <class T>
void put(std::vector<std::byte>& b, const T& v) {
  static_assert(std::is_standard_layout_v<T>);
  const std::size_t at = b.size();
  b.resize(at + sizeof(T));
  std::memcpy(b.data() + at, &v, sizeof(T));
}
template <class T>
T take(const std::vector<std::byte>& b, std::size_t& at) {
  static_assert(std::is_standard_layout_v<T>);
  T v;
  std::memcpy(static_cast<void*>(&v), b.data() + at, sizeof(T));
  at += sizeof(T);
  return v;
}
inline void put_string(std::vector<std::byte>& b, const std::string& s) {
  put<std::uint64_t>(b, s.size());
  const std::size_t at = b.size();
  b.resize(at + s.size());
  std::memcpy(b.data() + at, s.data(), s.size());
}
inline std::string take_string(const std::vector<std::byte>& b, std::size_t& at) {
  const auto n = take<std::uint64_t>(b, at);
  std::string s(reinterpret_cast<const char*>(b.data() + at), n);
  at += n;
  return s;
}

}  // namespace sph::par
