#include "nimbus/media/pattern_density.h"

#include <algorithm>
#include <cmath>

#include "nimbus/math/constants.h"

namespace nimbus {
namespace {

// Moves each octave's lattice off the others' (as fbm does), so they do not all vanish at 0.
constexpr Vec3 kTurbulenceShift{19.1, 7.3, 13.7};

}  // namespace

double turbulence(const Noise& n, const Vec3& q, int octaves) {
  double sum = 0, gain = 1, lacunarity = 1;
  for (int k = 0; k < octaves; ++k) {
    sum += gain * std::abs(noise(n, lacunarity * q + double(k) * kTurbulenceShift));
    gain *= 0.5;
    lacunarity *= 2;
  }
  return sum;
}

double PatternDensity::value(const Vec3& x, double) const {
  switch (p_.kind) {
    case PatternParams::Kind::Noise:
      return std::clamp(0.5 + fbm(noise_, p_.frequency * x, p_.octaves), 0.0, 1.0);
    case PatternParams::Kind::Turbulence:
      return std::min(1.0, turbulence(noise_, p_.frequency * x, p_.octaves));
    case PatternParams::Kind::Veins: {
      const double phase = 2 * kPi * p_.frequency * dot(p_.direction, x) +
                           p_.turbulence * turbulence(noise_, p_.noise_frequency * x, p_.octaves);
      const double band = std::clamp(0.5 * (1 + std::sin(phase)), 0.0, 1.0);
      return p_.sharpness == 1 ? band : std::pow(band, p_.sharpness);
    }
  }
  return 0;
}

DensityPtr make_pattern_density(const PatternParams& p) {
  return std::make_shared<PatternDensity>(p);
}

}  // namespace nimbus
