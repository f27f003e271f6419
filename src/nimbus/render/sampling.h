#pragma once
// Warps from the unit square to directions, with their solid-angle densities.

#include <algorithm>
#include <cmath>

#include "nimbus/math/constants.h"
#include "nimbus/math/vec3.h"

namespace nimbus {

inline Vec3 from_local(const Vec3& n, const Vec3& local) {
  Vec3 s, t;
  orthonormal_basis(n, s, t);
  return s * local.x + t * local.y + n * local.z;
}

// Cosine-weighted hemisphere around n; pdf = cos θ / π.
inline Vec3 sample_cosine_hemisphere(const Vec3& n, double u1, double u2) {
  const double r = std::sqrt(u1), phi = 2 * kPi * u2;
  return from_local(n, {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1 - u1))});
}

// Uniform over the sphere; pdf = 1 / 4π.
inline Vec3 sample_uniform_sphere(double u1, double u2) {
  const double z = 1 - 2 * u1, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Uniform within the cone of half-angle acos(cos_max) around n; pdf = 1 / (2π (1 − cos_max)).
inline Vec3 sample_uniform_cone(const Vec3& n, double cos_max, double u1, double u2) {
  const double z = 1 - u1 * (1 - cos_max), r = std::sqrt(std::max(0.0, 1 - z * z));
  const double phi = 2 * kPi * u2;
  return from_local(n, {r * std::cos(phi), r * std::sin(phi), z});
}

// Veach's power heuristic with β = 2, for one sample from each of two strategies.
inline double power_heuristic(double pdf_a, double pdf_b) {
  const double a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  return a + b > 0 ? a / (a + b) : 0.0;
}

}  // namespace nimbus
