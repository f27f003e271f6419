#pragma once
// Solid textures: scalar patterns of the point in 3-D, in [0, 1], made from the seeded gradient
// noise of noise.h. Each is a density type (density.h), so it can fill a medium as its density,
// and it can drive a textured parameter (a surface's albedo or roughness, a medium's sigma_a or
// sigma_s: docs/scene-format.md, "Textures"). With q = frequency · x:
//
//   noise       t = clamp(1/2 + fbm(q, octaves), 0, 1)
//   turbulence  t = min(1, T(q)),  T(q) = Σ_{k<octaves} 2^{-k} |noise(2^k q + k·shift)|
//   veins       t = ((1 + sin(2π frequency (d·x) + turbulence · T(noise_frequency · x))) /
//   2)^sharpness
//
// veins are Perlin's marble (1985): bands across the unit direction d, bent by turbulence; a
// sharpness above 1 thins the bands where the sine peaks into veins. No pattern has a useful
// bound tighter than [0, 1] over a box, so that is their range.

#include <cstdint>

#include "nimbus/math/vec3.h"
#include "nimbus/media/density.h"
#include "nimbus/media/noise.h"

namespace nimbus {

struct PatternParams {
  enum class Kind { Noise, Turbulence, Veins };
  Kind kind = Kind::Noise;
  double frequency = 1;  // noise and turbulence: lattice cells per unit; veins: bands per unit
  int octaves = 4;
  uint64_t seed = 0;
  // veins only
  Vec3 direction{1, 0, 0};     // unit: the bands run across it
  double turbulence = 4;       // the sine's phase distortion, in radians per unit of T
  double noise_frequency = 2;  // the turbulence's lattice cells per unit
  double sharpness = 1;        // exponent on the band profile (>= 1)
};

// |noise| summed over octaves as above: T in [0, fbm_bound(octaves)].
double turbulence(const Noise& n, const Vec3& q, int octaves);

class PatternDensity final : public Density {
 public:
  explicit PatternDensity(const PatternParams& p) : p_(p), noise_(make_noise(p.seed)) {}
  bool uses_F() const override { return false; }
  double value(const Vec3& x, double F) const override;
  Interval range(const Box&, const Interval&) const override { return {0.0, 1.0}; }
  const PatternParams& params() const { return p_; }

 private:
  PatternParams p_;
  Noise noise_;
};

DensityPtr make_pattern_density(const PatternParams& p);

}  // namespace nimbus
