#pragma once
// An exact sum of doubles (a long fixed-point accumulator in the manner of Kulisch): the result is the exact sum of
// everything added, rounded once to the nearest double (ties to even). So it is the same, bit for bit, whatever
// the order of the additions and however they are split into partial sums that are merged: across threads
// today, across ranks in a distributed run (issue #19), where each rank sums its own particles.
//
// Every finite double is an integer multiple of 2^-1074 below 2^1024, so a fixed-point integer whose bit 0 weighs
// 2^-1074 holds it exactly. The integer is kept in base 2^32, each digit in a signed 64-bit limb: an addition adds
// at most 2^32 - 1 (up or down) to three limbs without carrying, and carries are propagated only every 2^30
// additions or merges, and when the value is read.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace sph::par {

// 128-bit integers (GCC and clang; __extension__ keeps -Wpedantic quiet about them).
__extension__ typedef unsigned __int128 Uint128;
__extension__ typedef __int128 Int128;

class ExactSum {
 public:
  void add(double x) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &x, sizeof x);
    const auto biased = static_cast<int>((bits >> 52) & 0x7ffu);
    if (biased == 0x7ff) {  // Inf and NaN: summed apart and dominate the result, as in plain addition
      special_ += x;
      return;
    }
    // |x| = m 2^(p - 1074): a normal number has the implicit leading bit and p = biased exponent - 1, a
    // subnormal (biased 0) none and p = 0.
    std::uint64_t m = bits & ((std::uint64_t{1} << 52) - 1);
    int p = 0;
    if (biased != 0) {
      m |= std::uint64_t{1} << 52;
      p = biased - 1;
    }
    if (m == 0) return;
    const Uint128 v = static_cast<Uint128>(m) << (p % 32);
    const auto at = static_cast<std::size_t>(p / 32);
    const std::int64_t sign = (bits >> 63) != 0 ? -1 : 1;
    limb_[at] += sign * static_cast<std::int64_t>(static_cast<std::uint64_t>(v) & kDigitMask);
    limb_[at + 1] += sign * static_cast<std::int64_t>(static_cast<std::uint64_t>(v >> 32) & kDigitMask);
    limb_[at + 2] += sign * static_cast<std::int64_t>(static_cast<std::uint64_t>(v >> 64) & kDigitMask);
    count();
  }

  ExactSum& merge(const ExactSum& o) {
    for (std::size_t k = 0; k < kLimbs; ++k) limb_[k] += o.limb_[k];
    special_ += o.special_;
    pending_ += o.pending_;
    count();
    return *this;
  }

  /// The exact sum as doubles whose exact sum it is: the rounded sum, then the rounded remainder, and so on until
  /// nothing remains (a few for sums of like magnitudes). Adding them to an empty ExactSum restores this one's
  /// value exactly: the form a checkpoint keeps. Empty for zero; the special sum alone when Inf or NaN was added.
  std::vector<double> parts() const {
    if (special_ != 0.0 || std::isnan(special_)) return {special_};
    std::vector<double> out;
    ExactSum rest = *this;
    for (double v = rest.value(); v != 0.0 && std::isfinite(v); v = rest.value()) {
      out.push_back(v);
      rest.add(-v);
    }
    return out;
  }

  /// The exact sum rounded to the nearest double (ties to even); +-Inf beyond the largest double.
  double value() const {
    if (special_ != 0.0 || std::isnan(special_)) return special_;
    ExactSum t = *this;
    t.carry();
    bool negative = t.limb_[kLimbs - 1] < 0;
    if (negative) {  // the magnitude: negate every digit and carry again
      for (auto& l : t.limb_) l = -l;
      t.carry();
    }
    std::size_t h = kLimbs;
    while (h > 0 && t.limb_[h - 1] == 0) --h;
    if (h == 0) return 0.0;
    --h;  // the highest nonzero digit
    // The top three digits (at least 65 significant bits: the top digit is nonzero) and whether any digit below
    // them is nonzero (the sticky bit).
    const auto digit = [&](std::size_t k, std::size_t below) {
      return k >= below ? static_cast<Uint128>(static_cast<std::uint64_t>(t.limb_[k - below])) : 0;
    };
    const Uint128 w = (digit(h, 0) << 64) | (digit(h, 1) << 32) | digit(h, 2);
    bool sticky = false;
    for (std::size_t k = 0; k + 2 < h; ++k) sticky = sticky || t.limb_[k] != 0;
    int bits = 0;
    for (Uint128 u = w; u != 0; u >>= 1) ++bits;
    const int drop = bits - 53;  // >= 12
    auto mant = static_cast<std::uint64_t>(w >> drop);
    const Uint128 rest = w & ((static_cast<Uint128>(1) << drop) - 1);
    const Uint128 half = static_cast<Uint128>(1) << (drop - 1);
    if (rest > half || (rest == half && (sticky || (mant & 1u) != 0))) ++mant;  // 2^53 is still exact
    const int scale = drop + 32 * (static_cast<int>(h) - 2) - kBias;
    const double r = std::ldexp(static_cast<double>(mant), scale);
    return negative ? -r : r;
  }

 private:
  static constexpr int kBias = 1074;
  // Bits: 2098 for the doubles' range, 85 for one addend's reach above its position, 32 of headroom for carries.
  static constexpr std::size_t kLimbs = 72;
  static constexpr std::uint64_t kDigitMask = 0xffffffffu;
  static constexpr std::uint32_t kMaxPending = 1u << 30;

  void count() {
    if (++pending_ >= kMaxPending) carry();
  }
  /// Every digit but the top one into [0, 2^32); the top one keeps the sign.
  void carry() {
    for (std::size_t k = 0; k + 1 < kLimbs; ++k) {
      const std::int64_t c = limb_[k] >> 32;  // floor division by 2^32
      limb_[k] -= c * (std::int64_t{1} << 32);
      limb_[k + 1] += c;
    }
    pending_ = 0;
  }

  std::array<std::int64_t, kLimbs> limb_{};
  double special_ = 0.0;
  std::uint32_t pending_ = 0;
};

}  // namespace sph::par
