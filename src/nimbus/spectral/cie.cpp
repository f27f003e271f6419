#include "nimbus/spectral/cie.h"

#include "nimbus/spectral/spectral_tables.h"

namespace nimbus {

using namespace spectral_tables;

Vec3 cie_xyz_bar(double lambda) {
  return {interpolate(kCmf[0], lambda), interpolate(kCmf[1], lambda), interpolate(kCmf[2], lambda)};
}

double cie_y_integral() {
  static const double integral = [] {
    double sum = 0;
    for (int k = 0; k < kGridPoints; ++k) {
      sum += grid_weight(k) * interpolate(kCmf[1], grid_lambda(k));
    }
    return sum;
  }();
  return integral;
}

double d65_illuminant(double lambda) {
  // The same 1 nm trapezoid sum as emission_to_xyz, so that its luminance is 1 to rounding.
  static const double scale = [] {
    double y = 0;
    for (int k = 0; k < kGridPoints; ++k) {
      const double lambda_k = grid_lambda(k);
      y += grid_weight(k) * interpolate(kD65, lambda_k) * interpolate(kCmf[1], lambda_k);
    }
    return cie_y_integral() / y;
  }();
  return scale * interpolate(kD65, lambda);
}

}  // namespace nimbus
