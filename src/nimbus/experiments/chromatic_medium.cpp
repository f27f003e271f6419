#include "nimbus/experiments/chromatic_medium.h"

namespace nimbus {

ChromaticMedium homogeneous_medium(const Rgb& sigma_s) {
  ChromaticMedium m;
  m.sigma_s = sigma_s;
  return m;
}

ChromaticMedium uncorrelated_medium(const Rgb& sigma_s, double variation, double feature_size,
                                    uint64_t seed) {
  ChromaticMedium m;
  m.sigma_s = sigma_s;
  m.variation = variation;
  m.feature_size = feature_size;
  for (int i = 0; i < 3; ++i) m.noise[i] = make_noise(seed + 1 + i);
  return m;
}

MediumSample<3> medium_at(const ChromaticMedium& m, const Vec3& x) {
  MediumSample<3> s;
  s.mu_s = m.sigma_s;
  if (m.variation > 0) {
    const Vec3 p = x / m.feature_size;
    const double scale = m.variation / fbm_bound(m.octaves);
    for (int i = 0; i < 3; ++i) s.mu_s[i] *= 1 + scale * fbm(m.noise[i], p, m.octaves);
  }
  return s;
}

double majorant(const ChromaticMedium& m) {
  return m.sigma_s.max() * (1 + m.variation);
}

}  // namespace nimbus
