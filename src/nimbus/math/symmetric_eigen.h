#pragma once
// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations: slow next to closed
// forms but accurate for tiny and repeated eigenvalues, which is what classifying quadrics needs.

#include <array>

#include "nimbus/math/vec3.h"

namespace nimbus {

struct SymmetricEigen {
  std::array<double, 3> values;
  std::array<Vec3, 3> vectors;  // orthonormal; vectors[i] belongs to values[i]
};

SymmetricEigen symmetric_eigen(const std::array<std::array<double, 3>, 3>& a);

}  // namespace nimbus
