#pragma once
// The paper's second-order function (eq. 3):
//   F = A11 x² + A22 y² + A33 z² + A12 xy + A13 xz + A23 yz + A14 x + A24 y + A34 z + A44
// inside where F > 0. No factor 2 on the cross terms.

#include <algorithm>
#include <array>
#include <limits>

#include "nimbus/math/mat4.h"
#include "nimbus/math/ray.h"
#include "nimbus/math/vec3.h"

namespace nimbus {

struct Quadric {
  // A11 A22 A33 A12 A13 A23 A14 A24 A34 A44, in the paper's order.
  std::array<double, 10> a{};

  double eval(const Vec3& p) const {
    return p.x * (a[0] * p.x + a[3] * p.y + a[4] * p.z + a[6]) +
           p.y * (a[1] * p.y + a[5] * p.z + a[7]) + p.z * (a[2] * p.z + a[8]) + a[9];
  }
  Vec3 gradient(const Vec3& p) const {
    return {2 * a[0] * p.x + a[3] * p.y + a[4] * p.z + a[6],
            2 * a[1] * p.y + a[3] * p.x + a[5] * p.z + a[7],
            2 * a[2] * p.z + a[4] * p.x + a[5] * p.y + a[8]};
  }
  // eval and gradient where terms of opposite signs overflow into NaN (coefficients of 1e200,
  // an ellipsoid's radius of 1e-100, at coordinates of 1e100: +inf − inf): the same sums in
  // long double (an exponent range past 1e4900 on x86-64 and aarch64), rounded to the nearest
  // finite double. Every value that is not NaN is eval's and gradient's, bit for bit.
  double eval_finite(const Vec3& p) const {
    const double f = eval(p);
    return f == f ? f : clamped(wide_eval(p));
  }
  Vec3 gradient_finite(const Vec3& p) const {
    Vec3 g = gradient(p);
    if (g.x != g.x || g.y != g.y || g.z != g.z)
      for (int i = 0; i < 3; ++i) g[i] = clamped(wide_gradient(p, i));
    return g;
  }
  // The quadratic part alone, i.e. F's second-order term at direction d.
  double quadratic_form(const Vec3& d) const {
    return a[0] * d.x * d.x + a[1] * d.y * d.y + a[2] * d.z * d.z + a[3] * d.x * d.y +
           a[4] * d.x * d.z + a[5] * d.y * d.z;
  }

 private:
  static double clamped(long double x) {
    constexpr long double kMax = std::numeric_limits<double>::max();
    return x != x ? 0.0 : double(std::clamp(x, -kMax, kMax));
  }
  long double wide_eval(const Vec3& p) const {
    const long double x = p.x, y = p.y, z = p.z;
    return x * (a[0] * x + a[3] * y + a[4] * z + a[6]) + y * (a[1] * y + a[5] * z + a[7]) +
           z * (a[2] * z + a[8]) + a[9];
  }
  long double wide_gradient(const Vec3& p, int i) const {
    const long double x = p.x, y = p.y, z = p.z;
    if (i == 0) return 2 * x * a[0] + a[3] * y + a[4] * z + a[6];
    if (i == 1) return 2 * y * a[1] + a[3] * x + a[5] * z + a[7];
    return 2 * z * a[2] + a[4] * x + a[5] * y + a[8];
  }
};

// F along a ray: F(o + t d) = a t² + b t + c.
struct RayQuadratic {
  double a = 0, b = 0, c = 0;
  double at(double t) const { return (a * t + b) * t + c; }
  double derivative(double t) const { return 2 * a * t + b; }
};

inline RayQuadratic restrict_to_ray(const Quadric& q, const Ray& r) {
  return {q.quadratic_form(r.d), dot(q.gradient(r.o), r.d), q.eval(r.o)};
}

// The roots where a t² + b t + c changes sign, r0 < r1, in `roots`; returns how many (a double
// root changes no sign).
int sign_change_roots(const RayQuadratic& p, double roots[2]);

// The symmetric 4x4 matrix A with F = pᵀ A p on homogeneous p = (x, y, z, 1).
Mat4 to_matrix(const Quadric& q);
Quadric from_matrix(const Mat4& A);

// The same surface and inside with the coefficients scaled by a power of two (exactly) so that
// the largest magnitude lies in [1, 2): a quadric is defined up to a positive factor, and
// coefficients near a double's limits (1e308, 1e-300) would overflow or underflow F along a ray.
Quadric normalised(const Quadric& q);

// The quadric of the transformed object: F'(x) = F(M⁻¹ x), i.e. A' = M⁻ᵀ A M⁻¹.
// Only the coefficients change (paper §2.1). M must be invertible.
Quadric transformed(const Quadric& q, const Mat4& M);

}  // namespace nimbus
