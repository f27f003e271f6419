#pragma once
// Procedural cloud density of an object, from its function value F(x) (positive inside) and
// domain-warped fractal noise: a smooth profile of F eroded by noise, in the spirit of
// Schneider's Nubis erosion (the profile is "remapped" by the noise), with its own formula:
//
//   q = frequency · x
//   w = q + kWarp · (fbm(q + o₁, 2), fbm(q + o₂, 2), fbm(q + o₃, 2))     domain warp
//   ν = clamp(1/2 + kContrast · fbm(w, octaves), 0, 1)                  noise in [0, 1]
//   E = amplitude · (1 − ν)                                             erosion, in [0, amplitude]
//   s = smoothstep(0, edge, F) = 3u² − 2u³, u = clamp(F / edge, 0, 1)   profile, in [0, 1]
//   d = clamp((s − E) / (1 − E), 0, 1)                                  density, in [0, 1]
//
// Properties (amplitude in [0, 1), edge > 0):
// - d = 0 where F <= 0 (s = 0 there and E >= 0), and d rises continuously from the surface.
// - d is non-decreasing in F for fixed x (s is, and (s − E)/(1 − E) increases with s).
// - d is non-increasing in E for s <= 1 (∂/∂E = (s − 1)/(1 − E)² <= 0), so over a region where
//   F ∈ [F_lo, F_hi], with ν in the interval given by the global bound |fbm| <= fbm_bound:
//   d ∈ [d(s(F_lo), E_max), d(s(F_hi), E_min)] (cloud_density_range).
// Near the surface (s < amplitude) the noise eats the profile away where ν is low: billowy
// edges and holes. Deeper in (s > amplitude) the core is never empty but still textured, and
// where F >= edge (s = 1) the density is exactly 1.

#include <cstdint>
#include <utility>

#include "nimbus/math/vec3.h"
#include "nimbus/media/density.h"
#include "nimbus/media/noise.h"

namespace nimbus {

struct CloudParams {
  int octaves = 5;         // octaves of the eroding fbm
  double frequency = 2.0;  // noise frequency in the object's space (lattice cells per unit)
  double amplitude = 0.6;  // erosion depth in [0, 1): how far into the profile noise can eat
  uint64_t seed = 1;       // noise seed
  double edge = 1.0;       // F over which the profile rises from 0 to 1
};

inline constexpr double kCloudWarp = 0.6;      // domain-warp displacement, in noise cells
inline constexpr double kCloudContrast = 1.6;  // gain of fbm before mapping to [0, 1]
inline constexpr int kCloudWarpOctaves = 2;

// Parameters plus the noise tables built from the seed, ready to evaluate.
struct CloudNoise {
  CloudParams params;
  Noise noise;
  std::uint64_t id = 0;  // unique to each make_cloud_noise (copies share it): keys the memo below
};

CloudNoise make_cloud_noise(const CloudParams& params);

// The density d(x, F) above, in [0, 1].
double cloud_density(const CloudNoise& cloud, const Vec3& x, double F);

// A conservative [min, max] of cloud_density over any region where F ∈ [F_lo, F_hi].
std::pair<double, double> cloud_density_range(double F_lo, double F_hi, const CloudParams& params);

// The cloud as a medium's density (density.h).
class CloudDensity final : public Density {
 public:
  explicit CloudDensity(const CloudParams& params) : cloud_(make_cloud_noise(params)) {}
  bool uses_F() const override { return true; }
  double value(const Vec3& x, double F) const override { return cloud_density(cloud_, x, F); }
  Interval range(const Box&, const Interval& F) const override {
    const auto [lo, hi] = cloud_density_range(F.lo, F.hi, cloud_.params);
    return {lo, hi};
  }
  const CloudParams& params() const { return cloud_.params; }

 private:
  CloudNoise cloud_;
};

DensityPtr make_cloud_density(const CloudParams& params);

}  // namespace nimbus
