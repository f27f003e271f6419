#include "nimbus/spectral/wavelengths.h"

#include <algorithm>
#include <cmath>

namespace nimbus {
namespace {

// ∫ sech²(a(λ − μ)) dλ = tanh(a(λ − μ)) / a, so everything is closed form in these two values.
const double kTanhMin = std::tanh(kVisibleA * (kLambdaMin - kVisibleMu));
const double kTanhMax = std::tanh(kVisibleA * (kLambdaMax - kVisibleMu));

}  // namespace

double visible_wavelength_pdf(double lambda) {
  if (lambda < kLambdaMin || lambda > kLambdaMax) return 0;
  const double c = std::cosh(kVisibleA * (lambda - kVisibleMu));
  return kVisibleA / ((kTanhMax - kTanhMin) * c * c);
}

double visible_wavelength_cdf(double lambda) {
  if (lambda <= kLambdaMin) return 0;
  if (lambda >= kLambdaMax) return 1;
  return (std::tanh(kVisibleA * (lambda - kVisibleMu)) - kTanhMin) / (kTanhMax - kTanhMin);
}

double sample_visible_wavelength(double u) {
  const double t = kTanhMin + u * (kTanhMax - kTanhMin);
  // Clamped because rounding in atanh can step a hair outside the range at u = 0 or u → 1.
  return std::clamp(kVisibleMu + std::atanh(t) / kVisibleA, kLambdaMin, kLambdaMax);
}

}  // namespace nimbus
