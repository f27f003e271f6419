#include "nimbus/media/phase.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace nimbus {

double hg_phase(double cos_theta, double g) {
  // 1 + g² − 2 g cos θ, written as a sum of non-negative terms: as |g| → 1 the plain form
  // cancels to 0 or below at cos θ = ±1 (NaN and Inf pixels, issue 16), this one stays exact to
  // rounding: (1 − g)² + 2 g (1 − cos θ) for g >= 0, (1 + g)² − 2 g (1 + cos θ) for g < 0.
  // The cosine of two unit vectors can round past ±1, which would make the second term negative.
  const double c = std::clamp(cos_theta, -1.0, 1.0);
  const double denom =
      g >= 0 ? (1 - g) * (1 - g) + 2 * g * (1 - c) : (1 + g) * (1 + g) - 2 * g * (1 + c);
  return kInv4Pi * ((1 - g) * (1 + g)) / (denom * std::sqrt(denom));
}

double sample_hg_cos_theta(double g, double u1) {
  // Inverting P(cos θ <= c) = u1 gives, with a = 2 u1 − 1 and s = (1 − g²)/(1 + g a),
  // cos θ = (1 + g² − s²) / (2g). Multiplying out (1 + g²)(1 + g a)² − (1 − g²)² and dividing
  // by 2g removes the 0/0 at g = 0 (where cos θ = a, the isotropic inversion):
  // cos θ = [a + g (a² + 3)/2 + g² a + g³ (a² − 1)/2] / (1 + g a)².
  const double a = 2 * u1 - 1;
  const double num = a + g * (0.5 * (a * a + 3) + g * (a + 0.5 * g * (a * a - 1)));
  const double den = (1 + g * a) * (1 + g * a);
  return std::clamp(num / den, -1.0, 1.0);
}

Vec3 sample_hg(const Vec3& dir, double g, double u1, double u2) {
  const double cos_theta = sample_hg_cos_theta(g, u1);
  const double sin_theta = std::sqrt(std::max(0.0, 1 - cos_theta * cos_theta));
  const double phi = 2 * std::numbers::pi * u2;
  Vec3 s, t;
  orthonormal_basis(dir, s, t);
  return sin_theta * std::cos(phi) * s + sin_theta * std::sin(phi) * t + cos_theta * dir;
}

}  // namespace nimbus
