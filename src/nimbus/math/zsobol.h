#pragma once
// Owen-scrambled Sobol' points with pixels in Morton (Z) order (Ahmed & Wonka 2020, "Screen-space
// blue-noise diffusion of Monte Carlo sampling error via hierarchical ordering of pixels").
//
// One (0,2)-sequence in base 2, Sobol's first two dimensions, serves every dimension of a path.
// Sample s of pixel (x, y) takes the point at index morton(x, y) · 2^K + s with K =
// kZSobolSampleBits, so a pixel's samples are an aligned block of the sequence and every prefix of
// 2^m of them is a (0,m,2)-net: stratified in 2D and in each 1D projection. Each dimension d sees
// that index shuffled (shuffle_index): the pixel's base-4 Morton digits each by one of the 24
// permutations chosen by a hash of (d, the digits above it), the sample bits by a nested
// scramble; blocks stay blocks, while different dimensions pair their samples differently
// (decorrelated). Then the point gets an Owen scramble of its own.
//
// A sample's numbers depend on (seed, the film's size, pixel, sample index, dimension) and on
// nothing else: not on spp, so a render extended to more samples (a resumed checkpoint, issue 15)
// is the render made at that spp in one go, bit for bit. That is why K is fixed rather than
// ⌈log2 spp⌉ as in Ahmed & Wonka (2020), whose pixel blocks of exactly spp samples make a 2×2
// quad's samples a net too and so spread the error as blue noise across pixels: each pixel's own
// stratification, and with it its variance, is the same either way. Samples past 2^K start a
// fresh randomization per block of 2^K, so they never repeat a point.

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <stdexcept>

#include "nimbus/math/rng.h"

namespace nimbus {
namespace zsobol_detail {

constexpr uint64_t reverse_bits(uint64_t v) {
  v = ((v >> 1) & 0x5555555555555555ull) | ((v & 0x5555555555555555ull) << 1);
  v = ((v >> 2) & 0x3333333333333333ull) | ((v & 0x3333333333333333ull) << 2);
  v = ((v >> 4) & 0x0f0f0f0f0f0f0f0full) | ((v & 0x0f0f0f0f0f0f0f0full) << 4);
  v = ((v >> 8) & 0x00ff00ff00ff00ffull) | ((v & 0x00ff00ff00ff00ffull) << 8);
  v = ((v >> 16) & 0x0000ffff0000ffffull) | ((v & 0x0000ffff0000ffffull) << 16);
  return (v >> 32) | (v << 32);
}

// x's bits at the even positions of the result (a Morton code's x half).
constexpr uint64_t spread_bits(uint32_t x) {
  uint64_t v = x;
  v = (v | (v << 16)) & 0x0000ffff0000ffffull;
  v = (v | (v << 8)) & 0x00ff00ff00ff00ffull;
  v = (v | (v << 4)) & 0x0f0f0f0f0f0f0f0full;
  v = (v | (v << 2)) & 0x3333333333333333ull;
  v = (v | (v << 1)) & 0x5555555555555555ull;
  return v;
}

constexpr uint64_t morton(uint32_t x, uint32_t y) {
  return spread_bits(x) | (spread_bits(y) << 1);
}

// The 24 permutations of the base-4 digits {0, 1, 2, 3}.
constexpr std::array<std::array<uint8_t, 4>, 24> digit_permutations() {
  std::array<std::array<uint8_t, 4>, 24> out{};
  int k = 0;
  for (uint8_t a = 0; a < 4; ++a)
    for (uint8_t b = 0; b < 4; ++b)
      for (uint8_t c = 0; c < 4; ++c)
        if (a != b && a != c && b != c) out[k++] = {a, b, c, uint8_t(6 - a - b - c)};
  return out;
}
inline constexpr auto kDigitPermutations = digit_permutations();

// Sobol's second dimension: its generator is Pascal's matrix mod 2, so index bit c sets output
// digit r (the 2^-(r+1) place) where binom(c, r) is odd, i.e. where r's bits are a subset of c's
// (Lucas). Columns with digit r at bit r (the reversed fraction).
constexpr std::array<uint64_t, 64> pascal_columns() {
  std::array<uint64_t, 64> col{};
  for (uint64_t c = 0; c < 64; ++c)
    for (uint64_t r = 0; r <= c; ++r)
      if ((r & ~c) == 0) col[c] |= uint64_t(1) << r;
  return col;
}
inline constexpr auto kPascalColumns = pascal_columns();

// The same columns xored together for every value of each byte of the index: eight lookups
// instead of one per set bit.
constexpr std::array<std::array<uint64_t, 256>, 8> pascal_byte_tables() {
  std::array<std::array<uint64_t, 256>, 8> t{};
  for (int byte = 0; byte < 8; ++byte)
    for (int v = 0; v < 256; ++v)
      for (int bit = 0; bit < 8; ++bit)
        if (v & (1 << bit)) t[byte][v] ^= kPascalColumns[8 * byte + bit];
  return t;
}
inline constexpr auto kPascalBytes = pascal_byte_tables();

}  // namespace zsobol_detail

// The Sobol' point of index i in Sobol's dimension 0 (van der Corput) and 1, as reversed
// fractions: bit r holds the 2^-(r+1) digit. Dimension 0 reversed is the index itself.
constexpr uint64_t sobol0_reversed(uint64_t i) {
  return i;
}
constexpr uint64_t sobol1_reversed(uint64_t i) {
  uint64_t v = 0;
  for (int byte = 0; i != 0; ++byte, i >>= 8) v ^= zsobol_detail::kPascalBytes[byte][i & 0xff];
  return v;
}

// A nested uniform (Owen) scramble of a reversed fraction, hash-based (Laine & Karras 2011):
// adding the seed, multiplying by odd numbers and xoring a product with an even one change digit
// r as a function of the digits before it only, so elementary intervals map to elementary
// intervals and nets stay nets. The seed enters by the addition alone: digit r of the result is
// v's digit r xor the seed's digit r xor a function of lower digits, so with a random seed every
// scrambled point is uniform.
constexpr uint64_t owen_scramble_reversed(uint64_t v, uint64_t seed) {
  v += seed;
  v ^= v * 0x9e3779b97f4a7c16ull;
  v *= 0xbf58476d1ce4e5b9ull;
  v ^= v * 0x94d049bb133111eaull;
  v *= 0xd6e8feb86659fd93ull;
  v ^= v * 0x6a09e667f3bcc908ull;
  return v;
}

// The same with multipliers drawn from the seed too: a richer family of nested permutations, at
// three more hashes. The index shuffle takes it, as the pairing of one dimension's samples with
// another's rests on it alone (the additive family pairs neighbouring dimensions visibly).
constexpr uint64_t owen_scramble_reversed_rich(uint64_t v, uint64_t seed) {
  const uint64_t a = splitmix64(seed), b = splitmix64(a), c = splitmix64(b);
  v += a;
  v ^= v * (b << 1);
  v *= c | 1;
  v ^= v * 0x9e3779b97f4a7c16ull;
  v += b;
  v ^= v * (c << 1);
  return v;
}

// A reversed fraction as a double in [0, 1): its first 53 digits.
constexpr double reversed_to_unit(uint64_t v) {
  return static_cast<double>(zsobol_detail::reverse_bits(v) >> 11) * 0x1.0p-53;
}

// The index `morton · 2^sample_bits + s` as dimension `seed` sees it: the pixel's base-4 Morton
// digits permuted from the top, each by one of the 24 permutations picked by hashing the seed and
// the digits above it (Ahmed & Wonka), and s by a nested scramble of its bits from the top
// (Owen's scramble of the index, which pairs one dimension's samples with another's at random).
// A bijection that maps every aligned block of the pixel's samples, every pixel, and every
// aligned 2^j × 2^j block of pixels to an aligned block of the same size.
constexpr uint64_t shuffle_index(uint64_t index, int pixel_bits, int sample_bits, uint64_t seed) {
  const uint64_t pixel = index >> sample_bits;
  uint64_t out = 0;
  for (int p = pixel_bits - 2; p >= 0; p -= 2) {
    // The digits above, with a leading 1 so that prefixes of different lengths differ.
    const uint64_t node = (pixel >> (p + 2)) | (uint64_t(1) << (pixel_bits - p - 2));
    // One multiply-xorshift round mixes the node into the high half; their top bits pick the
    // permutation (by multiply-shift range reduction).
    uint64_t h = (node ^ seed) * 0xd6e8feb86659fd93ull;
    h ^= h >> 29;
    h *= 0x9e3779b97f4a7c15ull;
    const uint64_t pick = ((h >> 32) * 24) >> 32;
    out |= uint64_t(zsobol_detail::kDigitPermutations[pick][(pixel >> p) & 3]) << p;
  }
  if (sample_bits == 0) return out;
  // s's bits in the order of a reversed fraction (its top bit first), scrambled, and back.
  const uint64_t s = index & ((uint64_t(1) << sample_bits) - 1);
  const uint64_t r = zsobol_detail::reverse_bits(s << (64 - sample_bits));
  const uint64_t scrambled = owen_scramble_reversed_rich(r, seed ^ pixel);
  return (out << sample_bits) | (zsobol_detail::reverse_bits(scrambled) >> (64 - sample_bits));
}

// The sample bits of the index: a pixel's block of 2^16 samples (more start new blocks).
inline constexpr int kZSobolSampleBits = 16;

class ZSobol {
 public:
  // One pixel sample's place in the sequence.
  struct Key {
    uint64_t index;  // morton(x, y) · 2^K + (s mod 2^K), K = kZSobolSampleBits
    uint64_t seed;   // the render's seed with the block of 2^K samples that s is in
  };

  // For a film of width × height pixels; std::invalid_argument if the index would need more
  // than 62 bits (a side beyond 2^23 pixels).
  ZSobol(int width, int height, uint64_t seed) : seed_(seed) {
    if (width < 1 || height < 1)
      throw std::invalid_argument("zsobol: the film must be at least 1 pixel");
    const int log2_res = std::bit_width(uint32_t(std::max(width, height) - 1));
    pixel_bits_ = 2 * log2_res;
    if (pixel_bits_ + kZSobolSampleBits > 62)
      throw std::invalid_argument("zsobol: film beyond 2^46 pixels");
  }

  Key key(int x, int y, uint64_t sample) const {
    const uint64_t mask = (uint64_t(1) << kZSobolSampleBits) - 1;
    const uint64_t block = sample >> kZSobolSampleBits;
    return {
        (zsobol_detail::morton(uint32_t(x), uint32_t(y)) << kZSobolSampleBits) | (sample & mask),
        splitmix64(seed_ ^ splitmix64(block))};
  }

  // Dimension dim: one number, or two (a 2D point of the sequence).
  double get1d(const Key& k, uint32_t dim) const {
    const uint64_t h = dim_hash(k, dim);
    const uint64_t i = shuffle_index(k.index, pixel_bits_, kZSobolSampleBits, h);
    return reversed_to_unit(owen_scramble_reversed(sobol0_reversed(i), h ^ 0x51ed27062f3a8b4dull));
  }
  std::array<double, 2> get2d(const Key& k, uint32_t dim) const {
    const uint64_t h = dim_hash(k, dim);
    const uint64_t i = shuffle_index(k.index, pixel_bits_, kZSobolSampleBits, h);
    return {
        reversed_to_unit(owen_scramble_reversed(sobol0_reversed(i), h ^ 0x51ed27062f3a8b4dull)),
        reversed_to_unit(owen_scramble_reversed(sobol1_reversed(i), h ^ 0xa24baed4963ee407ull))};
  }

 private:
  static uint64_t dim_hash(const Key& k, uint32_t dim) {
    return splitmix64(k.seed ^ (uint64_t(dim) * 0x9e3779b97f4a7c15ull));
  }

  uint64_t seed_;
  int pixel_bits_ = 0;
};

}  // namespace nimbus
