#pragma once
// Axis-aligned boxes. An empty box has lo > hi; infinite extents are allowed.

#include <limits>

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

// Clips [t0, t1] to the part of the ray inside the box; false when nothing is left.
bool clip_ray(const Box& box, const Ray& ray, double& t0, double& t1);

}  // namespace nimbus
