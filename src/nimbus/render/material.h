#pragma once
// Surface scattering: opaque Lambertian, lossless dielectric and conductor, smooth or rough
// (render/microfacet.h), emitter. Directions are unit vectors; wo points away from the surface
// towards where the path came from.

#include "nimbus/math/vec3.h"
#include "nimbus/media/texture.h"
#include "nimbus/spectral/spectral_param.h"

namespace nimbus {

struct Surface {
  enum class Type { None, Diffuse, Dielectric, Emissive, Conductor };
  Type type = Type::Diffuse;
  SpectralParam albedo{Rgb(0.5)};  // role Albedo
  double ior = 1.5;
  SpectralParam radiance;           // role Illuminant
  double roughness = 0;             // dielectric, conductor: GGX α; 0 is the smooth (delta) case
  bool multiple_scattering = true;  // rough: give back the energy single scattering loses
  SpectralParam eta{Rgb(1.0)}, k{Rgb(0.0)};  // conductor: complex index η + ik, role Unbounded
  // Solid textures (media/texture.h): set, albedo and roughness are the values where t = 0 and
  // albedo_to and roughness_to those where t = 1.
  Texture albedo_texture, roughness_texture;
  SpectralParam albedo_to{Rgb(0.5)};  // role Albedo
  double roughness_to = 0;
};

// The rough boundary's GGX α at the surface point x, in the object's coordinates
// (texture_point, scene.h); the texture's F there is 0.
inline double roughness_at(const Surface& s, const Vec3& x) {
  return s.roughness_texture
             ? s.roughness + (s.roughness_to - s.roughness) * s.roughness_texture.at(x, 0.0)
             : s.roughness;
}

// A dielectric whose boundary is smooth: what manifold sampling looks through.
inline bool smooth_dielectric(const Surface& s) {
  return s.type == Surface::Type::Dielectric && s.roughness == 0;
}

// The conductor's reflectance at normal incidence, ((η − 1)² + k²) / ((η + 1)² + k²), per RGB
// channel: its colour for the albedo AOV and the preview.
Rgb conductor_reflectance(const Surface& s);

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
