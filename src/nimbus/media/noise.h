#pragma once
// Seeded 3D gradient noise (Perlin 1985/2002 style) and its fractal sum, with proven bounds.
//
// noise(x) = Σ_{c ∈ {0,1}³} w_c(t) · g_c · (t − c), where t = x − ⌊x⌋, g_c is the unit gradient
// hashed from the lattice corner ⌊x⌋ + c, and w_c(t) = Π_i (c_i ? S(t_i) : 1 − S(t_i)) with the
// quintic fade S(t) = 6t⁵ − 15t⁴ + 10t³.
//
// Bound |noise(x)| <= B = √3/2. Proof: w_c >= 0 and Σ_c w_c = 1, so by Cauchy–Schwarz and
// Jensen, |noise| <= Σ_c w_c |t − c| <= (Σ_c w_c |t − c|²)^{1/2}. The weights factor per axis,
// so Σ_c w_c |t − c|² = Σ_i h(t_i) with h(t) = (1 − S(t)) t² + S(t)(1 − t)² = t² + S(t)(1 − 2t).
// S(t) <= t on [0, 1/2] (S(t)/t = 6t⁴ − 15t³ + 10t² increases there to 1) and S(t) = 1 − S(1 − t),
// so S(t)(1 − 2t) <= t(1 − 2t) on all of [0, 1] and h(t) <= t(1 − t) <= 1/4. Hence
// |noise| <= (3/4)^{1/2}. The bound is attainable: at a cell centre whose eight gradients all point
// at it.
//
// fbm(x, K) = Σ_{k<K} gain^k noise(lacunarity^k x + k·shift), lacunarity 2, gain 1/2, and
// |fbm| <= B Σ_{k<K} 2^{−k} = B (2 − 2^{1−K}) = fbm_bound(K). The per-octave shift only moves
// the octaves' lattices apart (so they are not all zero at the origin); it does not change bounds.

#include <array>
#include <cstdint>

#include "nimbus/math/vec3.h"

namespace nimbus {

// √3/2: the bound of noise() proven above.
inline constexpr double kNoiseBound = 0.86602540378443864676;

// A permutation of 0..255 (Fisher–Yates from Rng(seed)) and 256 unit gradients, uniform on the
// sphere, drawn from the same stream.
struct Noise {
  std::array<uint8_t, 256> perm;
  std::array<Vec3, 256> grad;
};

Noise make_noise(uint64_t seed);

// Gradient noise at x; |noise| <= kNoiseBound, 0 on the integer lattice. Period 256 per axis.
double noise(const Noise& n, const Vec3& x);

// Fractal Brownian motion with `octaves` >= 0 octaves; |fbm| <= fbm_bound(octaves).
double fbm(const Noise& n, const Vec3& x, int octaves);
double fbm_bound(int octaves);

}  // namespace nimbus
