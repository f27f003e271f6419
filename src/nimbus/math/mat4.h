#pragma once
// Row-major 4x4 matrices of doubles for affine transforms of points (column vectors).

#include <array>

#include "nimbus/math/vec3.h"

namespace nimbus {

struct Mat4 {
  std::array<std::array<double, 4>, 4> m{};

  static Mat4 identity();
  static Mat4 translate(const Vec3& t);
  static Mat4 scale(const Vec3& s);
  // Rotation by `degrees` about `axis` (right-handed, counter-clockwise looking down the axis).
  static Mat4 rotate(const Vec3& axis, double degrees);

  double operator()(int r, int c) const { return m[r][c]; }
  double& operator()(int r, int c) { return m[r][c]; }
};

Mat4 operator*(const Mat4& a, const Mat4& b);
Mat4 transpose(const Mat4& a);
double determinant(const Mat4& a);
// Inverse by cofactors; the caller rejects near-singular matrices first (see determinant).
Mat4 inverse(const Mat4& a);
Vec3 transform_point(const Mat4& a, const Vec3& p);
Vec3 transform_vector(const Mat4& a, const Vec3& v);

}  // namespace nimbus
