#include "nimbus/frep/quadric.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace nimbus {

Mat4 to_matrix(const Quadric& q) {
  const auto& a = q.a;
  Mat4 A;
  A.m = {{{a[0], a[3] / 2, a[4] / 2, a[6] / 2},
          {a[3] / 2, a[1], a[5] / 2, a[7] / 2},
          {a[4] / 2, a[5] / 2, a[2], a[8] / 2},
          {a[6] / 2, a[7] / 2, a[8] / 2, a[9]}}};
  return A;
}

Quadric from_matrix(const Mat4& A) {
  // Symmetrise so that round-off in a product never leaks into the cross terms' halves.
  auto s = [&](int i, int j) { return A.m[i][j] + A.m[j][i]; };
  return {{A.m[0][0], A.m[1][1], A.m[2][2], s(0, 1), s(0, 2), s(1, 2), s(0, 3), s(1, 3), s(2, 3),
           A.m[3][3]}};
}

Quadric transformed(const Quadric& q, const Mat4& M) {
  const Mat4 Minv = inverse(M);
  return from_matrix(transpose(Minv) * to_matrix(q) * Minv);
}

Quadric normalised(const Quadric& q) {
  double largest = 0;
  for (double a : q.a) largest = std::max(largest, std::abs(a));
  if (!(largest > 0) || !std::isfinite(largest)) return q;
  Quadric n = q;
  const int e = std::ilogb(largest);
  for (double& a : n.a) a = std::ldexp(a, -e);
  return n;
}

// The cancellation-free pair q / a, c / q with q = −(b + sign(b) √disc) / 2; when a → 0 the root
// q / a runs off to ±∞ and c / q tends to the linear root −c / b, so a ≈ 0 needs no special case.
int sign_change_roots(const RayQuadratic& p, double roots[2]) {
  const double four_ac = 4 * p.a * p.c;
  double disc = p.b * p.b - four_ac;
  // Near a double root b² and 4ac cancel: recover the products' rounding errors by fma (Kahan).
  // Only then, since without -mfma every fma is a libm call.
  if (std::abs(disc) < 1e-6 * p.b * p.b)
    disc = std::fma(p.b, p.b, -four_ac) + std::fma(-4 * p.a, p.c, four_ac);
  if (!(disc > 0)) return 0;
  const double q = -0.5 * (p.b + std::copysign(std::sqrt(disc), p.b));
  double r0 = q / p.a, r1 = p.c / q;
  if (r0 > r1) std::swap(r0, r1);
  int count = 0;
  if (std::isfinite(r0)) roots[count++] = r0;
  if (std::isfinite(r1)) roots[count++] = r1;
  return count;
}

}  // namespace nimbus
