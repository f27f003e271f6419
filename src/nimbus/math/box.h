#pragma once
// Axis-aligned boxes. An empty box has lo > hi; infinite extents are allowed.

#include <limits>
#include <utility>

#include "nimbus/math/ray.h"
#include "nimbus/math/vec3.h"

namespace nimbus {

struct Box {
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  Vec3 lo{kInf, kInf, kInf};
  Vec3 hi{-kInf, -kInf, -kInf};

  static constexpr Box everything() { return {{-kInf, -kInf, -kInf}, {kInf, kInf, kInf}}; }
  constexpr bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  bool finite() const;
  constexpr Vec3 center() const { return (lo + hi) * 0.5; }
  constexpr Vec3 extent() const { return hi - lo; }
  constexpr bool contains(const Vec3& p) const {
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
  }
};

constexpr Box unite(const Box& a, const Box& b) {
  return {min(a.lo, b.lo), max(a.hi, b.hi)};
}
constexpr Box intersect(const Box& a, const Box& b) {
  return {max(a.lo, b.lo), min(a.hi, b.hi)};
}

// A ray with its direction's reciprocals, for clipping many boxes: the divisions once per ray.
struct RaySlabs {
  Vec3 o, inv;
  explicit RaySlabs(const Ray& r) : o(r.o), inv{1.0 / r.d.x, 1.0 / r.d.y, 1.0 / r.d.z} {}
};

// Clips [t0, t1] to the part of the ray inside the box; false when nothing is left.
inline bool clip_ray(const Box& box, const RaySlabs& ray, double& t0, double& t1) {
  if (box.empty()) return false;
  for (int i = 0; i < 3; ++i) {
    double ta = (box.lo[i] - ray.o[i]) * ray.inv[i];
    double tb = (box.hi[i] - ray.o[i]) * ray.inv[i];
    if (ta > tb) std::swap(ta, tb);
    // NaN arises for a zero direction component with the origin on a face: keep the interval.
    if (ta > t0) t0 = ta;
    if (tb < t1) t1 = tb;
    if (t0 > t1) return false;
  }
  return true;
}

inline bool clip_ray(const Box& box, const Ray& ray, double& t0, double& t1) {
  return clip_ray(box, RaySlabs(ray), t0, t1);
}

}  // namespace nimbus
