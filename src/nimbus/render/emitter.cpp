#include "nimbus/render/emitter.h"

#include <array>
#include <cmath>

#include "nimbus/frep/intersect.h"
#include "nimbus/math/box.h"
#include "nimbus/math/constants.h"
#include "nimbus/render/sampling.h"

namespace nimbus {
namespace {

// The roots of F along c + t u inside the object's bounds, nearest first; -1 if more than
// kMaxEmitterRoots.
int roots_along(const SceneObject& obj, const Ray& ray, std::array<double, kMaxEmitterRoots>& t) {
  double t0 = 0, t1 = kInf;
  if (!clip_ray(obj.bounds, ray, t0, t1)) return 0;
  int k = 0;
  for (double from = t0;;) {
    const auto hit = first_hit(obj.tape, ray, from, t1);
    if (!hit) return k;
    if (k == kMaxEmitterRoots) return -1;
    t[size_t(k++)] = *hit;
    from = *hit + 1e-9 * (1 + *hit);  // past the root: F has changed sign there
  }
}

}  // namespace

std::optional<EmitterPoint> sample_emitter_point(const Scene& scene, int object, double u1,
                                                 double u2, double u3) {
  const SceneObject& obj = scene.objects[size_t(object)];
  const Vec3 c = obj.bounds.center();
  const Ray ray{c, sample_uniform_sphere(u1, u2)};
  std::array<double, kMaxEmitterRoots> t;
  const int k = roots_along(obj, ray, t);
  if (k <= 0) return std::nullopt;
  const double tk = t[size_t(std::min(k - 1, static_cast<int>(u3 * k)))];
  EmitterPoint e;
  e.y = ray.at(tk);
  e.n = outward_normal(obj, e.y);
  e.pdf_area = std::abs(dot(e.n, ray.d)) / (4 * kPi * tk * tk * k);  // pdf_A, emitter.h
  if (!(e.pdf_area > 0) || !std::isfinite(e.pdf_area)) return std::nullopt;
  return e;
}

double emitter_point_pdf(const Scene& scene, int object, const Vec3& y, const Vec3& n) {
  const SceneObject& obj = scene.objects[size_t(object)];
  const Vec3 c = obj.bounds.center();
  const double r = length(y - c);
  if (!(r > 0)) return 0;
  const Ray ray{c, (y - c) / r};
  std::array<double, kMaxEmitterRoots> t;
  const int k = roots_along(obj, ray, t);
  if (k <= 0) return 0;
  const double pdf = std::abs(dot(n, ray.d)) / (4 * kPi * r * r * k);
  return std::isfinite(pdf) ? pdf : 0;
}

double emitter_solid_angle_pdf(const Scene& scene, int object, const Vec3& p, const Vec3& y,
                               const Vec3& n) {
  const Vec3 to = y - p;
  const double d2 = dot(to, to);
  const double cos_y = -dot(n, to) / std::sqrt(d2);
  if (!(cos_y > 0) || scene.emitters.empty()) return 0;
  const double pdf = emitter_point_pdf(scene, object, y, n) * d2 / cos_y /
                     static_cast<double>(scene.emitters.size());
  return std::isfinite(pdf) ? pdf : 0;
}

std::vector<int> emissive_objects(const Scene& scene) {
  std::vector<int> out;
  for (size_t i = 0; i < scene.objects.size(); ++i)
    if (scene.objects[i].surface.type == Surface::Type::Emissive) out.push_back(int(i));
  return out;
}

}  // namespace nimbus
