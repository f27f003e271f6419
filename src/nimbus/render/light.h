#pragma once
// Light sources: constant environment, directional (delta direction), point (delta position),
// and spherical area lights (sampled by the cone they subtend). Everything the renderer asks of
// a light is here and in light.cpp, one switch per question; the scene file's keys of each type
// are read by scene/light_types.cpp. A new light type is those three files.

#include <optional>

#include "nimbus/math/box.h"
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

// Whether rays that leave the scene meet the light (the environment): the path loop adds its
// radiance when a ray hits nothing.
bool at_infinity(const Light& light);

// Whether rays can hit the light's surface (a sphere): it is then in the scene's SurfaceIndex,
// found by intersect and blocking shadow rays to other lights.
bool has_surface(const Light& light);

// The box around the light's surface (a sphere light's ball); empty for lights without one.
Box surface_bounds(const Light& light);

// Nearest t in (t_min, t_max) where the ray (unit direction) meets the light's surface from
// outside; none for lights without one.
std::optional<double> intersect_light(const Light& light, const Ray& ray, double t_min,
                                      double t_max);

// The light's unoccluded fluence at p, ∫ L dω over the directions it covers, for an emission of
// `emission` (the average over a path's channels, >= 0): environment 4π L, directional E,
// point I / d², sphere L · 2π (1 − cos θ_max) (4π L inside). Light choice weighs lights by it.
double light_fluence(const Light& light, double emission, const Vec3& p);

}  // namespace nimbus
