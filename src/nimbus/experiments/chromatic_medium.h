#pragma once
// The unbounded, non-absorbing (albedo 1) chromatic media of the paper's Figs. 4–6: scattering
// only, with a different scattering coefficient per channel. Either homogeneous, where the
// distance to a scattering event of channel λ has the closed-form density
// sigma_s(λ) exp(−sigma_s(λ) t), or heterogeneous with spatially *uncorrelated* channels: each
// channel's coefficient is modulated by its own independent noise field,
//   sigma_s(x, λ) = sigma_s(λ) (1 + variation · fbm_λ(x / feature_size) / fbm_bound),
// so the channels vary independently in space, between (1 ± variation) sigma_s(λ).

#include <array>

#include "nimbus/math/vec3.h"
#include "nimbus/media/noise.h"
#include "nimbus/spectral/spectrum.h"
#include "nimbus/tracking/medium_sample.h"

namespace nimbus {

struct ChromaticMedium {
  Rgb sigma_s;           // per channel; the mean where heterogeneous
  double variation = 0;  // in [0, 1]; 0 is homogeneous
  double feature_size = 1;
  int octaves = 3;
  std::array<Noise, 3> noise;  // one independent field per channel
};

ChromaticMedium homogeneous_medium(const Rgb& sigma_s);
ChromaticMedium uncorrelated_medium(const Rgb& sigma_s, double variation, double feature_size,
                                    uint64_t seed);

// The coefficients at x: mu_a = 0, mu_s = sigma_s(x, ·), no emission.
MediumSample<3> medium_at(const ChromaticMedium& m, const Vec3& x);

// max_λ max_x sigma_s(x, λ): a majorant that bounds everywhere, so mu_n >= 0.
double majorant(const ChromaticMedium& m);

}  // namespace nimbus
