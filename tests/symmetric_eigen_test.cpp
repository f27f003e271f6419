#include "nimbus/math/symmetric_eigen.h"

#include <gtest/gtest.h>

#include <cmath>

#include "nimbus/math/rng.h"

namespace nimbus {
namespace symmetric_eigen_test {

using Matrix = std::array<std::array<double, 3>, 3>;

void expect_decomposes(const Matrix& a) {
  const SymmetricEigen e = symmetric_eigen(a);
  double scale = 0;
  for (const auto& row : a)
    for (double x : row) scale = std::max(scale, std::abs(x));
  for (int i = 0; i < 3; ++i) {
    const Vec3& v = e.vectors[i];
    for (int r = 0; r < 3; ++r) {
      const double av = a[r][0] * v.x + a[r][1] * v.y + a[r][2] * v.z;
      EXPECT_NEAR(av, e.values[i] * v[r], 1e-13 * (1 + scale));
    }
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(dot(e.vectors[i], e.vectors[j]), i == j ? 1.0 : 0.0, 1e-14);
  }
}

TEST(SymmetricEigen, DecomposesRandomMatrices) {
  Rng rng(9);
  for (int trial = 0; trial < 1000; ++trial) {
    Matrix a;
    for (int i = 0; i < 3; ++i)
      for (int j = i; j < 3; ++j) a[i][j] = a[j][i] = 2 * rng.uniform() - 1;
    expect_decomposes(a);
  }
}

TEST(SymmetricEigen, HandlesRepeatedAndZeroEigenvalues) {
  expect_decomposes({{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}});
  expect_decomposes({{{2, 0, 0}, {0, 2, 0}, {0, 0, 5}}});
  // n nᵀ: one eigenvalue |n|², two zeros.
  const Vec3 n{1, 2, 3};
  Matrix a;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a[i][j] = n[i] * n[j];
  expect_decomposes(a);
  const SymmetricEigen e = symmetric_eigen(a);
  int zeros = 0;
  for (double l : e.values) zeros += std::abs(l) < 1e-13;
  EXPECT_EQ(zeros, 2);
}

}  // namespace symmetric_eigen_test
}  // namespace nimbus
