#pragma once
/// \file Stratified pixel sampling: the first two dimensions of the Sobol sequence, scrambled
/// per pixel. Point s of a pixel depends only on (s, the pixel's key), so a progressive render
/// gets the same points whatever the pass sizes, and every prefix of 2^m points is stratified
/// (one point in each of the 2^m elementary intervals of any shape 2^-a x 2^-b, a + b = m).

#include <cstdint>
#include <utility>

#include "amalgam/math/random.h"

namespace amalgam {

/// The 32 bits of `x` in reverse order.
constexpr std::uint32_t reverse_bits(std::uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  return (x >> 16) | (x << 16);
}

/// A random scramble of a 32-bit binary fraction of the Owen type: binary digit k (counted
/// from the most significant) is flipped by a function of the digits before it only, so points
/// in one elementary interval stay together and a stratified set stays stratified. It works on
/// the reversed bits, where "digits before k" are the bits below k: adding a constant,
/// multiplying by an odd constant and x ^= x * even each change bit k by a function of the
/// lower bits alone, and each is a bijection. The constants come from `key` (a few
/// multiplications per value instead of one hash per digit).
constexpr std::uint32_t scramble_fraction(std::uint32_t v, std::uint64_t key) {
  const std::uint64_t h0 = mix64(key), h1 = mix64(h0);
  std::uint32_t x = reverse_bits(v);
  x += static_cast<std::uint32_t>(h0);
  x ^= x * (static_cast<std::uint32_t>(h0 >> 32) & ~1u);
  x *= static_cast<std::uint32_t>(h1) | 1u;
  x ^= x * (static_cast<std::uint32_t>(h1 >> 32) & ~1u);
  x += static_cast<std::uint32_t>(h1 >> 16);
  return reverse_bits(x);
}

/// Sample `index` of the 2-D Sobol sequence as 32-bit binary fractions: dimension 0 is the
/// van der Corput sequence (the bits of the index reversed), dimension 1 uses the direction
/// numbers of the primitive polynomial x + 1 (v_0 = 1/2, v_j = v_{j-1} ^ (v_{j-1} >> 1)).
constexpr std::pair<std::uint32_t, std::uint32_t> sobol_2d_bits(std::uint32_t index) {
  std::uint32_t y = 0, v = 1u << 31;
  for (std::uint32_t i = index; i != 0; i >>= 1, v ^= v >> 1)
    if (i & 1u) y ^= v;
  return {reverse_bits(index), y};
}

/// Sample `index` of the Sobol sequence in [0, 1)^2, each dimension scrambled with its own
/// constants derived from `key` (one key per pixel: the pixels' point sets are independent).
constexpr std::pair<float, float> scrambled_sobol_2d(std::uint32_t index, std::uint64_t key) {
  const auto [a, b] = sobol_2d_bits(index);
  const std::uint32_t x = scramble_fraction(a, hash_combine(key, 0));
  const std::uint32_t y = scramble_fraction(b, hash_combine(key, 1));
  constexpr float kUnit = 1.0f / 16777216.0f;  // top 24 bits: exact in a float, below 1
  return {static_cast<float>(x >> 8) * kUnit, static_cast<float>(y >> 8) * kUnit};
}

}  // namespace amalgam
