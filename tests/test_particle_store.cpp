// ParticleStore: every field travels with its particle through permutation, compaction and expansion
// (all gathers), append hands out fresh unique ids, and the registry covers every field. Values are
// assigned generically through for_each_field, so a field added later is covered as soon as it is
// registered (and a field of a new type fails to compile in value_for until the test learns the type).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "core/field.hpp"
#include "core/particle_store.hpp"
#include "core/types.hpp"
#include "parallel/compaction.hpp"

namespace sph {
namespace {

template <class T>
[[maybe_unused]] inline constexpr bool kAlwaysFalse = false;  // only read by the static_assert of an unhandled type

/// The value field number `salt` of the particle with this id carries. Distinct across ids and fields.
template <class T>
T value_for(ParticleId id, int salt) {
  const auto base = static_cast<double>(id) * 64.0 + static_cast<double>(salt);
  if constexpr (std::is_same_v<T, double>) {
    return base + 0.25;
  } else if constexpr (std::is_same_v<T, std::int32_t>) {
    return static_cast<std::int32_t>(id % 1000003) * 64 + salt;
  } else if constexpr (std::is_same_v<T, ParticleId>) {
    return id * 64 + static_cast<ParticleId>(salt);
  } else if constexpr (std::is_same_v<T, Kind>) {
    return static_cast<Kind>((id + static_cast<ParticleId>(salt)) % 3);
  } else if constexpr (std::is_same_v<T, Origin>) {
    return static_cast<Origin>((id + static_cast<ParticleId>(salt)) % 4);
  } else if constexpr (std::is_same_v<T, Role>) {
    return static_cast<Role>((id + static_cast<ParticleId>(salt)) % 4);
  } else if constexpr (requires { T::RowsAtCompileTime; }) {
    T v;
    for (Eigen::Index k = 0; k < v.size(); ++k) v[k] = base + 0.5 + static_cast<double>(k) * 1e-3;
    return v;
  } else {
    static_assert(kAlwaysFalse<T>, "value_for: teach the test this field type");
  }
}

template <class F, class Store>
bool is_id_field(const F& f, const Store& s) {
  return static_cast<const void*>(&f) == static_cast<const void*>(&s.id);
}

/// Fills every field but id with values derived from the particle's id and the field's position in the
/// registry.
template <int D>
void fill_from_ids(ParticleStore<D>& s) {
  int salt = 0;
  s.for_each_field([&](auto& f) {
    using T = typename std::decay_t<decltype(f)>::value_type;
    ++salt;
    if (is_id_field(f, s)) return;
    for (std::size_t k = 0; k < f.size(); ++k) f[k] = value_for<T>(s.id[k], salt);
  });
}

/// Counts, over all fields but id, the entries that do not carry their particle's values.
template <int D>
std::size_t inconsistent_entries(const ParticleStore<D>& s) {
  std::size_t bad = 0;
  int salt = 0;
  s.for_each_field([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::value_type;
    ++salt;
    if (f.size() != s.size()) {
      ADD_FAILURE() << "field " << f.name() << " has " << f.size() << " entries, the store " << s.size();
      ++bad;
      return;
    }
    if (is_id_field(f, s)) return;
    for (std::size_t k = 0; k < f.size(); ++k) {
      if (!(f[k] == value_for<T>(s.id[k], salt))) {
        if (bad < 5) ADD_FAILURE() << "field " << f.name() << " at index " << k << " (id " << s.id[k] << ")";
        ++bad;
      }
    }
  });
  return bad;
}

template <int D>
ParticleStore<D> filled_store(std::size_t n) {
  ParticleStore<D> s;
  s.append(n);
  fill_from_ids(s);
  return s;
}

std::vector<ParticleId> ids_of(const Field<ParticleId>& id) {
  return id.values();
}

template <class Dim>
class ParticleStoreTest : public ::testing::Test {
 public:
  static constexpr int kDim = Dim::value;
};
using Dims = ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(ParticleStoreTest, Dims);

TYPED_TEST(ParticleStoreTest, RegistryCoversEveryFieldAndBytesPerParticleMatchesIt) {
  constexpr int D = TestFixture::kDim;
  ParticleStore<D> s;
  std::size_t fields = 0;
  std::size_t bytes = 0;
  std::set<std::string> names;
  s.for_each_field([&](const auto& f) {
    ++fields;
    bytes += sizeof(typename std::decay_t<decltype(f)>::value_type);
    names.insert(std::string(f.name()));
  });
  EXPECT_EQ(names.size(), fields) << "field names must be unique";
  EXPECT_EQ(bytes, ParticleStore<D>::bytes_per_particle());
  // Every field of the class is in the registry: the class holds nothing but Fields and next_id_.
  EXPECT_EQ(fields * sizeof(Field<double>) + sizeof(ParticleId), sizeof(ParticleStore<D>));
}

TYPED_TEST(ParticleStoreTest, AppendGivesZeroedFieldsAndFreshIds) {
  constexpr int D = TestFixture::kDim;
  ParticleStore<D> s;
  EXPECT_TRUE(s.empty());
  EXPECT_EQ(s.append(10), 0u);
  EXPECT_EQ(s.append(5), 10u);
  EXPECT_EQ(s.size(), 15u);
  EXPECT_EQ(s.next_id(), 15u);
  for (std::size_t k = 0; k < s.size(); ++k) EXPECT_EQ(s.id[k], k);
  s.for_each_field([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::value_type;
    EXPECT_EQ(f.size(), 15u) << f.name();
    if (is_id_field(f, s)) return;
    for (std::size_t k = 0; k < f.size(); ++k)
      EXPECT_TRUE(f[k] == zero_value<T>()) << f.name() << " at " << k;
  });
}

TYPED_TEST(ParticleStoreTest, PermutationKeepsEveryFieldWithItsParticle) {
  constexpr int D = TestFixture::kDim;
  const std::size_t n = 10007;
  ParticleStore<D> s = filled_store<D>(n);
  ASSERT_EQ(inconsistent_entries(s), 0u);
  std::vector<std::uint32_t> perm(n);
  std::iota(perm.begin(), perm.end(), 0u);
  std::mt19937 rng(1);
  for (int round = 0; round < 3; ++round) {  // repeated gathers reuse the scratch buffers
    std::shuffle(perm.begin(), perm.end(), rng);
    const std::vector<ParticleId> before = ids_of(s.id);
    s.gather(perm);
    ASSERT_EQ(s.size(), n);
    for (std::size_t k = 0; k < n; ++k) ASSERT_EQ(s.id[k], before[perm[k]]);
    EXPECT_EQ(inconsistent_entries(s), 0u);
  }
  std::vector<ParticleId> ids = ids_of(s.id);
  std::sort(ids.begin(), ids.end());
  for (std::size_t k = 0; k < n; ++k) ASSERT_EQ(ids[k], k) << "a permutation loses or duplicates no particle";
  EXPECT_EQ(s.next_id(), n);
}

TYPED_TEST(ParticleStoreTest, CompactionKeepsSurvivorsInOrderWithTheirFields) {
  constexpr int D = TestFixture::kDim;
  const std::size_t n = 10007;
  ParticleStore<D> s = filled_store<D>(n);
  s.compact([&](std::size_t i) { return s.id[i] % 3 != 0; });
  std::vector<ParticleId> expected;
  for (ParticleId id = 0; id < n; ++id) {
    if (id % 3 != 0) expected.push_back(id);
  }
  EXPECT_EQ(ids_of(s.id), expected);
  EXPECT_EQ(inconsistent_entries(s), 0u);
  // Compaction through an explicit increasing gather, after a shuffle.
  std::vector<std::uint32_t> perm(s.size());
  std::iota(perm.begin(), perm.end(), 0u);
  std::shuffle(perm.begin(), perm.end(), std::mt19937(2));
  s.gather(perm);
  const std::vector<ParticleId> before = ids_of(s.id);
  const auto keep = par::compaction_map(s.size(), [&](std::size_t i) { return before[i] % 2 == 0; });
  s.gather(keep);
  ASSERT_EQ(s.size(), keep.size());
  for (std::size_t k = 0; k < keep.size(); ++k) ASSERT_EQ(s.id[k], before[keep[k]]);
  EXPECT_EQ(inconsistent_entries(s), 0u);
  // Down to nothing and back.
  s.compact([](std::size_t) { return false; });
  EXPECT_TRUE(s.empty());
  EXPECT_EQ(inconsistent_entries(s), 0u);
}

TYPED_TEST(ParticleStoreTest, ExpansionCopiesEveryFieldToEachCopyAtAnyThreadCount) {
  constexpr int D = TestFixture::kDim;
  const std::size_t n = 5003;  // the static worksharing loops split unevenly across threads
  for (const int threads : {1, 2, 3}) {
    SCOPED_TRACE(threads);
    ParticleStore<D> s = filled_store<D>(n);
    // Particle i becomes id % 4 copies (0 removes it): a gather with repeated indices.
    std::vector<std::uint32_t> offsets;
    const auto src = par::expansion_map(
        n, [&](std::size_t i) { return static_cast<std::uint32_t>(s.id[i] % 4); }, &offsets);
    const int saved = omp_get_max_threads();
    omp_set_num_threads(threads);
    s.gather(src);
    omp_set_num_threads(saved);
    ASSERT_EQ(s.size(), src.size());
    for (std::size_t i = 0; i < n; ++i) {
      for (std::uint32_t k = offsets[i]; k < offsets[i + 1]; ++k) ASSERT_EQ(s.id[k], i);
    }
    // Copies carry the same values, so consistency by id covers them all.
    EXPECT_EQ(inconsistent_entries(s), 0u);
    // The refinement step then gives the copies fresh ids; they do not collide with any id ever handed out.
    const ParticleId first = s.take_ids(s.size());
    EXPECT_EQ(first, n);
    EXPECT_EQ(s.next_id(), n + s.size());
  }
}

TYPED_TEST(ParticleStoreTest, AppendAfterRemovalNeverReusesIds) {
  constexpr int D = TestFixture::kDim;
  ParticleStore<D> s = filled_store<D>(1000);
  s.compact([&](std::size_t i) { return s.id[i] >= 500; });  // drop the lower ids
  const std::size_t first = s.append(300);
  EXPECT_EQ(first, 500u);
  std::set<ParticleId> ids(s.id.values().begin(), s.id.values().end());
  EXPECT_EQ(ids.size(), s.size()) << "ids are unique";
  for (std::size_t k = first; k < s.size(); ++k) EXPECT_GE(s.id[k], 1000u) << "fresh ids are new";
  EXPECT_EQ(s.next_id(), 1300u);
  // The appended particles get the generic values too and travel with a permutation like the rest.
  fill_from_ids(s);
  std::vector<std::uint32_t> perm(s.size());
  std::iota(perm.begin(), perm.end(), 0u);
  std::shuffle(perm.begin(), perm.end(), std::mt19937(3));
  s.gather(perm);
  EXPECT_EQ(inconsistent_entries(s), 0u);
}

TYPED_TEST(ParticleStoreTest, ResizeReserveAndClearApplyToEveryField) {
  constexpr int D = TestFixture::kDim;
  ParticleStore<D> s = filled_store<D>(100);
  s.reserve(1000);
  s.for_each_field([](const auto& f) { EXPECT_GE(f.values().capacity(), 1000u) << f.name(); });
  s.resize(40);
  EXPECT_EQ(inconsistent_entries(s), 0u);  // also checks every field has 40 entries
  s.clear();
  EXPECT_TRUE(s.empty());
  EXPECT_EQ(inconsistent_entries(s), 0u);
  EXPECT_EQ(s.next_id(), 100u) << "clearing the particles does not rewind the id counter";
}

TYPED_TEST(ParticleStoreTest, ViewPointsAtTheFields) {
  constexpr int D = TestFixture::kDim;
  ParticleStore<D> s = filled_store<D>(10);
  const ParticleView<D> v = s.view();
  EXPECT_EQ(v.n, 10u);
  EXPECT_EQ(v.x, s.x.data());
  EXPECT_EQ(v.v, s.v.data());
  EXPECT_EQ(v.rho, s.rho.data());
  EXPECT_EQ(v.p, s.p.data());
  EXPECT_EQ(v.m, s.m.data());
  EXPECT_EQ(v.h, s.h.data());
  EXPECT_EQ(v.d, s.d.data());
  EXPECT_EQ(v.level, s.level.data());
  EXPECT_EQ(v.kind, s.kind.data());
  EXPECT_EQ(v.id, s.id.data());
  EXPECT_EQ(v.drho, s.drho.data());
  EXPECT_EQ(v.a, s.a.data());
  EXPECT_EQ(v.vh, s.vh.data());
  EXPECT_EQ(v.rhoh, s.rhoh.data());
}

TYPED_TEST(ParticleStoreTest, AssignFromCopiesEveryFieldAndTheNextIdAtAnyThreadCount) {
  constexpr int D = TestFixture::kDim;
  // 10,007 particles: the static worksharing loops split unevenly across threads.
  const ParticleStore<D> source = filled_store<D>(10007);
  for (const int threads : {1, 2, 3}) {
    SCOPED_TRACE(threads);
    const int saved = omp_get_max_threads();
    omp_set_num_threads(threads);
    ParticleStore<D> copy = filled_store<D>(5);  // smaller: must grow
    copy.set_next_id(3);
    copy.assign_from(source);
    omp_set_num_threads(saved);
    EXPECT_EQ(copy.size(), source.size());
    EXPECT_EQ(copy.next_id(), source.next_id());
    EXPECT_EQ(ids_of(copy.id), ids_of(source.id));
    EXPECT_EQ(inconsistent_entries(copy), 0u);
    // And back down to a smaller store.
    const ParticleStore<D> small = filled_store<D>(17);
    copy.assign_from(small);
    EXPECT_EQ(copy.size(), 17u);
    EXPECT_EQ(inconsistent_entries(copy), 0u);
  }
}

TEST(ParticleStore, GatherAllocatesNothingOnceAtSize) {
  ParticleStore<2> s = filled_store<2>(1000);
  std::vector<std::uint32_t> perm(1000);
  std::iota(perm.begin(), perm.end(), 0u);
  std::reverse(perm.begin(), perm.end());
  s.gather(perm);
  s.gather(perm);
  const std::size_t bytes = s.bytes();
  const double* x_before = &s.x[0][0];
  s.gather(perm);
  s.gather(perm);
  EXPECT_EQ(s.bytes(), bytes);
  EXPECT_EQ(&s.x[0][0], x_before) << "two gathers swap the same two buffers back";
  EXPECT_EQ(inconsistent_entries(s), 0u);
}

}  // namespace
}  // namespace sph
