#include "nimbus/render/material.h"

#include <cmath>

namespace nimbus {

Rgb conductor_reflectance(const Surface& s) {
  Rgb r(0.0);
  for (int c = 0; c < 3; ++c) {
    const double eta = s.eta.rgb[c], k2 = s.k.rgb[c] * s.k.rgb[c];
    r[c] = ((eta - 1) * (eta - 1) + k2) / ((eta + 1) * (eta + 1) + k2);
  }
  return r;
}

double fresnel_dielectric(double cos_i, double eta) {
  const double sin2_t = (1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) return 1.0;  // total internal reflection
  const double cos_t = std::sqrt(1 - sin2_t);
  const double r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  const double r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5 * (r_par * r_par + r_perp * r_perp);
}

DielectricSample sample_dielectric(const Vec3& wo, const Vec3& n, double ior, double u) {
  double cos_i = dot(wo, n);
  Vec3 nf = n;
  double eta = ior;
  if (cos_i < 0) {  // leaving the solid
    cos_i = -cos_i;
    nf = -n;
    eta = 1 / ior;
  }
  const double F = fresnel_dielectric(cos_i, eta);
  if (u < F) return {nf * (2 * cos_i) - wo, true, F};
  const double sin2_t = (1 - cos_i * cos_i) / (eta * eta);
  const double cos_t = std::sqrt(std::max(0.0, 1 - sin2_t));
  return {normalize(-wo / eta + nf * (cos_i / eta - cos_t)), false, F};
}

}  // namespace nimbus
