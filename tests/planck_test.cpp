// Planck's law in absolute units (spectral/planck.h, issue 14): the radiance integrates to
// Stefan–Boltzmann's σT⁴/π, the curve is the law itself, and planck_rgb's table agrees with the
// integration it replaces at every temperature, from a glow to T → ∞.

#include "nimbus/spectral/planck.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "nimbus/math/constants.h"
#include "nimbus/math/rng.h"
#include "nimbus/spectral/color.h"

namespace nimbus {
namespace planck_test {

TEST(Planck, RadianceIntegratesToStefanBoltzmann) {
  constexpr double kSigma = 5.670374419e-8;  // W·m⁻²·K⁻⁴
  for (double kelvin : {300.0, 1500.0, 6500.0}) {
    // The trapezoid rule in log λ over 10 nm .. 10 mm: B λ is smooth there and negligible
    // beyond (below 1e-9 of the total).
    const int steps = 200000;
    const double a = std::log(10.0), b = std::log(1e7), h = (b - a) / steps;
    double sum = 0;
    for (int i = 0; i <= steps; ++i) {
      const double lambda = std::exp(a + i * h);
      sum += (i == 0 || i == steps ? 0.5 : 1.0) * planck_radiance(lambda, kelvin) * lambda;
    }
    const double expected = kSigma * std::pow(kelvin, 4) / kPi;
    EXPECT_NEAR(sum * h / expected, 1.0, 1e-6) << kelvin << " K";
  }
  EXPECT_EQ(planck_radiance(0, 1000), 0.0);
  EXPECT_EQ(planck_radiance(500, 0), 0.0);
  EXPECT_EQ(planck_radiance(1, 300), 0.0);  // the exponential overflows: no emission, no NaN
}

TEST(Planck, TheCurveIsTheLaw) {
  for (double kelvin : {500.0, 1800.0, 6500.0, 1e5})
    for (double lambda = 360; lambda <= 830; lambda += 7) {
      const double b = planck_radiance(lambda, kelvin);
      EXPECT_NEAR(planck_spectrum(kelvin)(lambda) / b, 1.0, 1e-13) << kelvin << " K " << lambda;
    }
}

// The table interpolates log(Y/T) and the chromaticity linearly in 1/T; both are smooth there, so
// the error is of order (step)² times their curvature. Measured: at most 6e-8 (relative to the
// largest channel) over these temperatures.
TEST(Planck, RgbTableAgreesWithTheIntegration) {
  Rng rng(3);
  double worst = 0;
  auto check = [&](double kelvin) {
    Rgb exact = emission_to_rgb(planck_spectrum(kelvin));
    for (int c = 0; c < 3; ++c) exact[c] = std::max(exact[c], 0.0);
    const Rgb table = planck_rgb(kelvin);
    const double err = (table - exact).max_abs() / exact.max_abs();
    worst = std::max(worst, err);
    EXPECT_LT(err, 1e-6) << kelvin << " K";
  };
  for (double kelvin :
       {100.0, 399.0, 400.0, 500.0, 798.0, 1000.0, 1800.0, 3000.0, 6504.0, 1e5, 1e7, 1e10})
    check(kelvin);
  for (int i = 0; i < 2000; ++i) check(std::exp(std::log(400.0) + rng.uniform() * std::log(1e5)));
  RecordProperty("worst_relative_error", fmt::format("{:.3g}", worst));
  EXPECT_EQ(planck_rgb(0).max_abs(), 0.0);
  EXPECT_EQ(planck_rgb(-5).max_abs(), 0.0);
}

}  // namespace planck_test
}  // namespace nimbus
