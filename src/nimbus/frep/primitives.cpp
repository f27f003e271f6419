#include "nimbus/frep/primitives.h"

#include <cmath>
#include <numbers>

namespace nimbus {
namespace {

// The quadric  s·|x − p|² + u·((x − p)·a)² + l·(x − p) + k, expanded into eq. 3's coefficients.
Quadric expand(const Vec3& p, double s, double u, const Vec3& a, const Vec3& l, double k) {
  // Quadratic part as a symmetric 3x3 matrix S = s I + u a aᵀ.
  double S[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) S[i][j] = (i == j ? s : 0.0) + u * a[i] * a[j];
  // Linear part: −2 S p + l; constant: pᵀ S p − l·p + k.
  Vec3 Sp{};
  for (int i = 0; i < 3; ++i) Sp[i] = S[i][0] * p.x + S[i][1] * p.y + S[i][2] * p.z;
  const Vec3 lin = l - 2.0 * Sp;
  const double c = dot(p, Sp) - dot(l, p) + k;
  return {
      {S[0][0], S[1][1], S[2][2], 2 * S[0][1], 2 * S[0][2], 2 * S[1][2], lin.x, lin.y, lin.z, c}};
}

}  // namespace

Quadric sphere(const Vec3& center, double radius) {
  return expand(center, -1.0, 0.0, {}, {}, radius * radius);
}

Quadric ellipsoid(const Vec3& center, const Vec3& radii) {
  const Vec3 inv{1 / (radii.x * radii.x), 1 / (radii.y * radii.y), 1 / (radii.z * radii.z)};
  const Vec3& c = center;
  return {{-inv.x, -inv.y, -inv.z, 0, 0, 0, 2 * inv.x * c.x, 2 * inv.y * c.y, 2 * inv.z * c.z,
           1 - inv.x * c.x * c.x - inv.y * c.y * c.y - inv.z * c.z * c.z}};
}

Quadric cylinder(const Vec3& point, const Vec3& axis, double radius) {
  // r² − (|x−p|² − ((x−p)·a)²)
  return expand(point, -1.0, 1.0, normalize(axis), {}, radius * radius);
}

Quadric cone(const Vec3& apex, const Vec3& axis, double half_angle_degrees) {
  const double th = half_angle_degrees * std::numbers::pi / 180.0;
  const double c2 = std::cos(th) * std::cos(th);
  return expand(apex, -c2, 1.0, normalize(axis), {}, 0.0);
}

Quadric paraboloid(const Vec3& vertex, const Vec3& axis, double focal_length) {
  const Vec3 a = normalize(axis);
  return expand(vertex, -1.0, 1.0, a, 4.0 * focal_length * a, 0.0);
}

Quadric halfspace(const Vec3& point, const Vec3& normal) {
  return expand(point, 0.0, 0.0, {}, -normalize(normal), 0.0);
}

Quadric slab(const Vec3& center, const Vec3& normal, double thickness) {
  return expand(center, 0.0, -1.0, normalize(normal), {}, 0.25 * thickness * thickness);
}

ShapePtr box(const Vec3& lo, const Vec3& hi) {
  const Vec3 c = (lo + hi) * 0.5, e = hi - lo;
  CsgNode node{CsgOp::Intersection, {}};
  const Vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int i = 0; i < 3; ++i)
    node.children.push_back(make_shape(QuadricNode{slab(c, axes[i], e[i])}));
  return make_shape(std::move(node));
}

}  // namespace nimbus
