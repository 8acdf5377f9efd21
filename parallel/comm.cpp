#include "parallel/comm.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <stdexcept>

#ifdef SPH_MPI
#include <mpi.h>
#endif

namespace sph::par {

namespace {

Comm& the_world() {
  static Comm world;
  return world;
}

#ifdef SPH_MPI
MPI_Comm mpi(const Comm& c) { return static_cast<MPI_Comm>(c.native()); }

void check(int code, const char* what) {
  if (code != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + what + " failed");
}

std::vector<int> displacements(const std::vector<int>& counts) {
  std::vector<int> d(counts.size(), 0);
  for (std::size_t r = 1; r < counts.size(); ++r) d[r] = d[r - 1] + counts[r - 1];
  return d;
}

/// One value reduced over every rank (itself in one process).
template <class T>
T reduced(const Comm& c, T x, MPI_Datatype type, MPI_Op op) {
  if (c.native() != nullptr) check(MPI_Allreduce(MPI_IN_PLACE, &x, 1, type, op, mpi(c)), "allreduce");
  return x;
}

int as_count(std::size_t n) {
  if (n > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    throw std::length_error("MPI: a message of more than 2 GiB (" + std::to_string(n) + " bytes)");
  }
  return static_cast<int>(n);
}
#endif

void set_from(std::vector<std::size_t>* from, const std::vector<int>& counts) {
  if (from == nullptr) return;
  from->assign(counts.begin(), counts.end());
}

}  // namespace

const Comm& Comm::world() { return the_world(); }

double Comm::min(double x) const {
#ifdef SPH_MPI
  return reduced(*this, x, MPI_DOUBLE, MPI_MIN);
#else
  return x;
#endif
}

double Comm::max(double x) const {
#ifdef SPH_MPI
  return reduced(*this, x, MPI_DOUBLE, MPI_MAX);
#else
  return x;
#endif
}

std::uint64_t Comm::sum(std::uint64_t x) const {
#ifdef SPH_MPI
  return reduced(*this, x, MPI_UINT64_T, MPI_SUM);
#else
  return x;
#endif
}

bool Comm::any(bool x) const {
#ifdef SPH_MPI
  return reduced(*this, x ? 1 : 0, MPI_INT, MPI_MAX) != 0;
#else
  return x;
#endif
}

ExactSum Comm::sum(const ExactSum& x) const {
  if (size_ == 1) return x;
  ExactSum total;
  for (const ExactSum& part : all_gather_value(x)) total.merge(part);
  return total;
}

std::vector<std::byte> Comm::exchange(const std::vector<std::vector<std::byte>>& out,
                                      std::vector<std::size_t>* from) const {
  if (out.size() != static_cast<std::size_t>(size_)) throw std::logic_error("Comm::exchange: one buffer per rank");
#ifdef SPH_MPI
  if (native_ != nullptr) {
    std::vector<int> send_counts(out.size()), recv_counts(out.size());
    for (std::size_t r = 0; r < out.size(); ++r) send_counts[r] = as_count(out[r].size());
    check(MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, mpi(*this)), "alltoall");
    const std::vector<int> send_at = displacements(send_counts), recv_at = displacements(recv_counts);
    std::vector<std::byte> send(static_cast<std::size_t>(send_at.back() + send_counts.back()));
    for (std::size_t r = 0; r < out.size(); ++r) {
      if (!out[r].empty()) std::memcpy(send.data() + send_at[r], out[r].data(), out[r].size());
    }
    std::vector<std::byte> recv(static_cast<std::size_t>(recv_at.back() + recv_counts.back()));
    check(MPI_Alltoallv(send.data(), send_counts.data(), send_at.data(), MPI_BYTE, recv.data(), recv_counts.data(),
                        recv_at.data(), MPI_BYTE, mpi(*this)),
          "alltoallv");
    set_from(from, recv_counts);
    return recv;
  }
#endif
  set_from(from, {static_cast<int>(out[0].size())});
  return out[0];
}

std::vector<std::byte> Comm::all_gather(const std::vector<std::byte>& mine, std::vector<std::size_t>* from) const {
#ifdef SPH_MPI
  if (native_ != nullptr) {
    int n = as_count(mine.size());
    std::vector<int> counts(static_cast<std::size_t>(size_), 0);
    check(MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, mpi(*this)), "allgather");
    const std::vector<int> at = displacements(counts);
    std::vector<std::byte> all(static_cast<std::size_t>(at.back() + counts.back()));
    check(MPI_Allgatherv(mine.data(), n, MPI_BYTE, all.data(), counts.data(), at.data(), MPI_BYTE, mpi(*this)),
          "allgatherv");
    set_from(from, counts);
    return all;
  }
#endif
  set_from(from, {static_cast<int>(mine.size())});
  return mine;
}

void Comm::barrier() const {
#ifdef SPH_MPI
  if (native_ != nullptr) check(MPI_Barrier(mpi(*this)), "barrier");
#endif
}

int Session::launched_ranks() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "MPI_LOCALNRANKS"}) {
    if (const char* v = std::getenv(name)) return std::max(1, std::atoi(v));
  }
  return 1;
}

bool Session::built_with_mpi() {
#ifdef SPH_MPI
  return true;
#else
  return false;
#endif
}

Session::Session(int& argc, char**& argv) {
  const bool launched = std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMI_SIZE") != nullptr ||
                        std::getenv("PMIX_RANK") != nullptr;
#ifdef SPH_MPI
  if (!launched) return;
  int provided = 0;
  // Funneled: OpenMP threads compute, only the thread that started MPI calls it.
  check(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "init");
  started_ = true;
  Comm& w = the_world();
  w.native_ = static_cast<void*>(MPI_COMM_WORLD);
  MPI_Comm_rank(MPI_COMM_WORLD, &w.rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &w.size_);
  if (w.size_ == 1) {  // one rank: the run is the one-process run, without MPI in the step
    w.native_ = nullptr;
  }
#else
  (void)argc;
  (void)argv;
  if (launched && launched_ranks() > 1) {
    throw std::runtime_error("this sphrefine was built without MPI, and " + std::to_string(launched_ranks()) +
                             " ranks were launched: each would run the whole scene. Build the mpi preset "
                             "(scripts/build mpi) to run across processes");
  }
#endif
}

void Session::abort(int code) {
  std::fflush(stdout);
  std::fflush(stderr);
#ifdef SPH_MPI
  int started = 0;
  MPI_Initialized(&started);
  if (started != 0) MPI_Abort(MPI_COMM_WORLD, code);
#endif
  std::exit(code);
}

Session::~Session() {
#ifdef SPH_MPI
  if (started_) MPI_Finalize();
#endif
}

}  // namespace sph::par
