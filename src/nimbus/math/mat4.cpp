#include "nimbus/math/mat4.h"

#include <cmath>
#include <numbers>

namespace nimbus {

Mat4 Mat4::identity() {
  Mat4 r;
  for (int i = 0; i < 4; ++i) r.m[i][i] = 1.0;
  return r;
}

Mat4 Mat4::translate(const Vec3& t) {
  Mat4 r = identity();
  r.m[0][3] = t.x;
  r.m[1][3] = t.y;
  r.m[2][3] = t.z;
  return r;
}

Mat4 Mat4::scale(const Vec3& s) {
  Mat4 r = identity();
  r.m[0][0] = s.x;
  r.m[1][1] = s.y;
  r.m[2][2] = s.z;
  return r;
}

Mat4 Mat4::rotate(const Vec3& axis, double degrees) {
  const Vec3 a = normalize(axis);
  const double th = degrees * std::numbers::pi / 180.0;
  const double c = std::cos(th), s = std::sin(th), k = 1.0 - c;
  Mat4 r = identity();
  r.m[0] = {c + a.x * a.x * k, a.x * a.y * k - a.z * s, a.x * a.z * k + a.y * s, 0};
  r.m[1] = {a.y * a.x * k + a.z * s, c + a.y * a.y * k, a.y * a.z * k - a.x * s, 0};
  r.m[2] = {a.z * a.x * k - a.y * s, a.z * a.y * k + a.x * s, c + a.z * a.z * k, 0};
  return r;
}

Mat4 operator*(const Mat4& a, const Mat4& b) {
  Mat4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a.m[i][k] * b.m[k][j];
      r.m[i][j] = s;
    }
  return r;
}

Mat4 transpose(const Mat4& a) {
  Mat4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = a.m[j][i];
  return r;
}

namespace {
double minor3(const Mat4& a, int row, int col) {
  double s[3][3];
  for (int i = 0, si = 0; i < 4; ++i) {
    if (i == row) continue;
    for (int j = 0, sj = 0; j < 4; ++j) {
      if (j == col) continue;
      s[si][sj++] = a.m[i][j];
    }
    ++si;
  }
  return s[0][0] * (s[1][1] * s[2][2] - s[1][2] * s[2][1]) -
         s[0][1] * (s[1][0] * s[2][2] - s[1][2] * s[2][0]) +
         s[0][2] * (s[1][0] * s[2][1] - s[1][1] * s[2][0]);
}
}  // namespace

double determinant(const Mat4& a) {
  double d = 0;
  for (int j = 0; j < 4; ++j) d += ((j % 2) ? -1.0 : 1.0) * a.m[0][j] * minor3(a, 0, j);
  return d;
}

Mat4 inverse(const Mat4& a) {
  const double inv_det = 1.0 / determinant(a);
  Mat4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      r.m[j][i] = (((i + j) % 2) ? -1.0 : 1.0) * minor3(a, i, j) * inv_det;
  return r;
}

Vec3 transform_point(const Mat4& a, const Vec3& p) {
  return {a.m[0][0] * p.x + a.m[0][1] * p.y + a.m[0][2] * p.z + a.m[0][3],
          a.m[1][0] * p.x + a.m[1][1] * p.y + a.m[1][2] * p.z + a.m[1][3],
          a.m[2][0] * p.x + a.m[2][1] * p.y + a.m[2][2] * p.z + a.m[2][3]};
}

Vec3 transform_vector(const Mat4& a, const Vec3& v) {
  return {a.m[0][0] * v.x + a.m[0][1] * v.y + a.m[0][2] * v.z,
          a.m[1][0] * v.x + a.m[1][1] * v.y + a.m[1][2] * v.z,
          a.m[2][0] * v.x + a.m[2][1] * v.y + a.m[2][2] * v.z};
}

}  // namespace nimbus
