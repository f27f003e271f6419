#pragma once
// Surface scattering: opaque Lambertian, smooth lossless dielectric, emitter. Directions are
// unit vectors; wo points away from the surface towards where the path came from.

#include "nimbus/math/vec3.h"
#include "nimbus/spectral/spectral_param.h"

namespace nimbus {

struct Surface {
  enum class Type { None, Diffuse, Dielectric, Emissive };
  Type type = Type::Diffuse;
  SpectralParam albedo{Rgb(0.5)};  // role Albedo
  double ior = 1.5;
  SpectralParam radiance;  // role Illuminant
};

// Unpolarised Fresnel reflectance at a smooth interface; eta = n_transmitted / n_incident.
double fresnel_dielectric(double cos_i, double eta);

struct DielectricSample {
  Vec3 wi;
  bool reflected;
  double F;  // the Fresnel reflectance, the probability of reflection
};
// Chooses reflection with probability F, else refraction, so the path weight stays unchanged
// (the interface is lossless). n is the outward normal of a solid of index `ior` in vacuum.
DielectricSample sample_dielectric(const Vec3& wo, const Vec3& n, double ior, double u);

}  // namespace nimbus
