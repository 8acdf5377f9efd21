// The ranks' building blocks in one process (issue #19; the runs across ranks are tests/mpi/): the communicator
// of a process without an MPI launcher is one rank whose collectives return what they were given, and a particle
// packed for another rank comes back with every field of the store's registry, bit for bit.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "core/case_builder.hpp"
#include "core/domain.hpp"
#include "parallel/comm.hpp"
#include "tests/support/io_helpers.hpp"

namespace sph {
namespace {

TEST(Comm, OneProcessIsOneRankWhoseCollectivesReturnWhatTheyGet) {
  const par::Comm& c = par::Comm::world();
  EXPECT_EQ(c.rank(), 0);
  EXPECT_EQ(c.size(), 1);
  EXPECT_FALSE(c.distributed());
  EXPECT_EQ(c.min(2.5), 2.5);
  EXPECT_EQ(c.max(-1.0), -1.0);
  EXPECT_EQ(c.sum(std::uint64_t{7}), 7u);
  EXPECT_TRUE(c.any(true));
  EXPECT_FALSE(c.any(false));
  par::ExactSum s;
  s.add(1e16);
  s.add(1.0);
  s.add(-1e16);
  EXPECT_EQ(c.sum(s).value(), 1.0);
  const std::vector<std::byte> bytes{std::byte{1}, std::byte{2}, std::byte{3}};
  std::vector<std::size_t> from;
  EXPECT_EQ(c.exchange({bytes}, &from), bytes);
  EXPECT_EQ(from, std::vector<std::size_t>{3});
  EXPECT_EQ(c.all_gather(bytes), bytes);
  EXPECT_EQ(c.all_gather_value(42), std::vector<int>{42});
  EXPECT_EQ(c.all_gather_values(std::vector<double>{1.5, -2.0}), (std::vector<double>{1.5, -2.0}));
  EXPECT_THROW(c.exchange({bytes, bytes}), std::logic_error) << "one buffer per rank";
}

TEST(Comm, ValuesAndStringsReadBackAsWritten) {
  std::vector<std::byte> b;
  par::put(b, 3.25);
  par::put_string(b, "a report");
  par::put(b, Vec<3>(1.0, -2.0, 0.5));
  par::put<std::uint8_t>(b, 9);
  std::size_t at = 0;
  EXPECT_EQ(par::take<double>(b, at), 3.25);
  EXPECT_EQ(par::take_string(b, at), "a report");
  EXPECT_EQ(par::take<Vec<3>>(b, at), Vec<3>(1.0, -2.0, 0.5));
  EXPECT_EQ(par::take<std::uint8_t>(b, at), 9);
  EXPECT_EQ(at, b.size());
}

TEST(Comm, APackedParticleComesBackWithEveryField) {
  Simulation sim = make_dam_break(DamBreakSpec{});
  for (int k = 0; k < 20; ++k) sim.step();  // rates, half-step state and ghosts all non-trivial
  const ParticleStore<2>& s = sim.store();
  std::vector<std::byte> bytes;
  for (std::size_t i = 0; i < s.size(); ++i) pack_particle(s, i, bytes);
  EXPECT_EQ(bytes.size(), s.size() * packed_size<2>());
  ParticleStore<2> back;
  back.set_next_id(s.next_id());
  EXPECT_EQ(unpack_particles(back, bytes), 0u);
  test::expect_bitwise_equal(s, back);
  // Appended after what is there, in order.
  EXPECT_EQ(unpack_particles(back, bytes), s.size());
  EXPECT_EQ(back.size(), 2 * s.size());
  EXPECT_EQ(back.id[s.size() + 5], s.id[5]);
}

}  // namespace
}  // namespace sph
