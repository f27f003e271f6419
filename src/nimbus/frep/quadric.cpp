#include "nimbus/frep/quadric.h"

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

}  // namespace nimbus
