#pragma once
// One per-particle array of the store, with a name, the unit of its values, and a scratch buffer reused by
// gathers so that reordering allocates nothing once the store has reached its size.
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <utility>
#include <vector>


namespace sph {

/// The value new entries start with: zero for numbers and for Eigen vectors (whose T{} is uninitialised).
template <class T>
T zero_value() {
  if constexpr (requires { T::Zero(); }) {
    return T::Zero();
  } else {
    return T{};
  }
}

template <class T>
class Field {
 public:
  using value_type = T;
  /// `unit`: the SI unit of the values as UDUNITS text ("m", "m/s", "kg/m^3", "Pa"; "1" for counts, ids and
  /// labels); output writes it beside the values (the HDF5 datasets' `units` attribute).
  Field(std::string_view name, std::string_view unit) : name_(name), unit_(unit) {}

  std::string_view name() const { return name_; }
  std::string_view unit() const { return unit_; }
  std::size_t size() const { return data_.size(); }
  T* data() { return data_.data(); }
  const T* data() const { return data_.data(); }
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  std::vector<T>& values() { return data_; }
  const std::vector<T>& values() const { return data_; }

  void resize(std::size_t n) { data_.resize(n, zero_value<T>()); }
  void reserve(std::size_t n) { data_.reserve(n); }

  /// A gather in three parts, so that the store gathers all its fields in one parallel region
  /// (ParticleStore::gather): size the scratch (serial: it may allocate), fill it from any thread through
  /// gather_scratch(), then swap it in with gather_commit().
  void prepare_gather(std::size_t m) { scratch_.resize(m); }
  T* gather_scratch() { return scratch_.data(); }
  void gather_commit() { std::swap(data_, scratch_); }

  std::size_t bytes() const { return (data_.capacity() + scratch_.capacity()) * sizeof(T); }

 private:
  std::string_view name_;
  std::string_view unit_;
  std::vector<T> data_;
  std::vector<T> scratch_;
};

}  // namespace sph
