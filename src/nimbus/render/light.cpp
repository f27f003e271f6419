#include "nimbus/render/light.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "nimbus/math/constants.h"
#include "nimbus/render/sampling.h"

namespace nimbus {
namespace {

double sphere_cos_max(const Light& l, double dist2) {
  const double sin2 = l.radius * l.radius / dist2;
  return std::sqrt(std::max(0.0, 1 - sin2));
}
}  // namespace

std::optional<LightSample> sample_light(const Light& light, const Vec3& p, double u1, double u2) {
  switch (light.type) {
    case Light::Type::Environment:
      return LightSample{sample_uniform_sphere(u1, u2), kInf, 1.0, kInv4Pi, false};
    case Light::Type::Directional:
      return LightSample{-light.direction, kInf, 1.0, 0, true};
    case Light::Type::Point: {
      const Vec3 d = light.position - p;
      const double d2 = dot(d, d);
      return LightSample{d / std::sqrt(d2), std::sqrt(d2), 1 / d2, 0, true};
    }
    case Light::Type::Sphere: {
      const Vec3 d = light.center - p;
      const double d2 = dot(d, d);
      if (d2 <= light.radius * light.radius) return std::nullopt;
      const double cos_max = sphere_cos_max(light, d2);
      const Vec3 axis = d / std::sqrt(d2);
      const Vec3 wi = sample_uniform_cone(axis, cos_max, u1, u2);
      const auto t = intersect_light(light, {p, wi}, 0, kInf);
      // The cone is tangent to the sphere; a direction at its rim can round to a miss.
      const double dist = t ? *t : std::sqrt(d2 - light.radius * light.radius);
      return LightSample{wi, dist, 1.0, 1 / (2 * kPi * (1 - cos_max)), false};
    }
  }
  return std::nullopt;
}

double light_pdf(const Light& light, const Vec3& p, const Vec3& w) {
  switch (light.type) {
    case Light::Type::Environment:
      return kInv4Pi;
    case Light::Type::Directional:
    case Light::Type::Point:
      return 0;
    case Light::Type::Sphere: {
      const Vec3 d = light.center - p;
      const double d2 = dot(d, d);
      if (d2 <= light.radius * light.radius) return 0;
      const double cos_max = sphere_cos_max(light, d2);
      if (dot(w, d) < cos_max * std::sqrt(d2)) return 0;
      return 1 / (2 * kPi * (1 - cos_max));
    }
  }
  return 0;
}

bool at_infinity(const Light& light) {
  return light.type == Light::Type::Environment;
}

bool has_surface(const Light& light) {
  return light.type == Light::Type::Sphere;
}

Box surface_bounds(const Light& light) {
  if (!has_surface(light)) return {};
  const Vec3 r{light.radius, light.radius, light.radius};
  return {light.center - r, light.center + r};
}

double light_fluence(const Light& light, double e, const Vec3& p) {
  switch (light.type) {
    case Light::Type::Environment:
      return 4 * kPi * e;
    case Light::Type::Directional:
      return e;
    case Light::Type::Point:
      return e / std::max(dot(p - light.position, p - light.position), 1e-300);
    case Light::Type::Sphere: {
      const double d2 = dot(p - light.center, p - light.center), r2 = light.radius * light.radius;
      if (d2 <= r2) return 4 * kPi * e;
      const double sin2 = r2 / d2;
      // 1 − cos θ_max = sin² / (1 + cos), accurate for small spheres far away.
      return 2 * kPi * e * sin2 / (1 + std::sqrt(1 - sin2));
    }
  }
  return 0;
}

std::optional<double> intersect_light(const Light& light, const Ray& ray, double t_min,
                                      double t_max) {
  if (light.type != Light::Type::Sphere) return std::nullopt;
  const Vec3 oc = ray.o - light.center;
  const double b = dot(oc, ray.d);
  const double c = dot(oc, oc) - light.radius * light.radius;
  if (c <= 0) return std::nullopt;  // inside: the light is seen only from outside
  const double disc = b * b - c;
  if (disc < 0) return std::nullopt;
  const double t = -b - std::sqrt(disc);
  if (t <= t_min || t >= t_max) return std::nullopt;
  return t;
}

}  // namespace nimbus
