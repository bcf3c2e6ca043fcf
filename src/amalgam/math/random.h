#pragma once
/// \file Counter-based random numbers: every random decision is a pure function of
/// (seed, pixel, sample, ray, object), so images do not depend on thread count or on the
/// order in which a traversal happens to meet objects.

#include <cstdint>

namespace amalgam {

/// SplitMix64 finaliser: a bijective 64-bit mixer (Steele, Lea, Flood 2014).
constexpr std::uint64_t mix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

/// Combines a running key with one more value.
constexpr std::uint64_t hash_combine(std::uint64_t key, std::uint64_t value) {
  return mix64(key ^ mix64(value));
}

/// Maps 64 random bits to a float uniform in [0, 1), using the top 24 bits.
constexpr float to_unit_float(std::uint64_t bits) {
  return static_cast<float>(bits >> 40) * (1.0f / 16777216.0f);
}

/// A tiny sequential generator over a counter: dimension d of stream `key` is
/// to_unit_float(hash_combine(key, d)).
class Sampler {
 public:
  constexpr explicit Sampler(std::uint64_t key) : key_(key) {}
  constexpr float next() { return to_unit_float(hash_combine(key_, counter_++)); }
  constexpr std::uint64_t key() const { return key_; }

 private:
  std::uint64_t key_;
  std::uint64_t counter_ = 0;
};

}  // namespace amalgam
