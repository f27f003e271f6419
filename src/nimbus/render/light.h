#pragma once
// Light sources: constant environment, directional (delta direction), point (delta position),
// and spherical area lights (sampled by the cone they subtend).

#include <optional>

#include "nimbus/math/ray.h"
#include "nimbus/math/vec3.h"
#include "nimbus/spectral/spectral_param.h"

namespace nimbus {

struct Light {
  enum class Type { Environment, Directional, Point, Sphere };
  Type type = Type::Environment;
  // Radiance (environment, sphere), irradiance on a plane normal to the beam (directional) or
  // intensity (point); role Illuminant.
  SpectralParam emission;
  Vec3 direction;     // directional: the direction light travels (unit)
  Vec3 position;      // point
  Vec3 center;        // sphere
  double radius = 0;  // sphere
};

// Incident light at p from one sampled direction: Li = falloff times the light's emission (at the
// path's channels). pdf is a solid-angle density, or 0 with `delta` set for directional and point
// lights.
struct LightSample {
  Vec3 wi;          // towards the light, unit
  double distance;  // to the emitting point (infinity for distant lights)
  double falloff;   // 1 / distance² for a point light, else 1
  double pdf = 0;
  bool delta = false;
};

std::optional<LightSample> sample_light(const Light& light, const Vec3& p, double u1, double u2);

// Solid-angle density with which sample_light picks direction w from p (0 for delta lights and
// for a sphere light that p is inside of).
double light_pdf(const Light& light, const Vec3& p, const Vec3& w);

// Nearest t > t_min where the ray (unit direction) meets a sphere light's surface from outside.
std::optional<double> intersect_sphere_light(const Light& light, const Ray& ray, double t_min,
                                             double t_max);

}  // namespace nimbus
