// The spectral module (issue 8): the wavelength pdf and its stratified estimator, the CIE tables,
// XYZ ↔ linear sRGB, RGB-to-spectrum upsampling and its round trips, exact ranges, piecewise
// linear curves and blackbodies. The round-trip tolerances sit a little above the errors measured
// with the 48³ table (docs/spectra.md).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "nimbus/math/rng.h"
#include "nimbus/spectral/cie.h"
#include "nimbus/spectral/color.h"
#include "nimbus/spectral/spectral_curve.h"
#include "nimbus/spectral/wavelengths.h"
#include "support/stats.h"

namespace nimbus {
namespace spectral_test {

using test::simpson;

double max_abs_diff(const Rgb& a, const Rgb& b) {
  return std::max({std::abs(a[0] - b[0]), std::abs(a[1] - b[1]), std::abs(a[2] - b[2])});
}

Vec3 chromaticity(const Vec3& xyz) {
  const double sum = xyz.x + xyz.y + xyz.z;
  return {xyz.x / sum, xyz.y / sum, xyz.z / sum};
}

// The colours of an n³ grid over [0, scale]³.
std::vector<Rgb> grid_colours(int n, double scale) {
  std::vector<Rgb> colours;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        colours.push_back(Rgb({double(i), double(j), double(k)}) * (scale / (n - 1)));
  return colours;
}

// ---------------------------------------------------------------------------------------------
// Wavelength sampling

TEST(SpectralWavelengths, PdfIntegratesToOne) {
  // The pdf is smooth on [360, 830]: Simpson with 4700 intervals is accurate to ~1e-14.
  EXPECT_NEAR(simpson(visible_wavelength_pdf, kLambdaMin, kLambdaMax, 4700), 1.0, 1e-12);
  EXPECT_EQ(visible_wavelength_pdf(kLambdaMin - 1), 0);
  EXPECT_EQ(visible_wavelength_pdf(kLambdaMax + 1), 0);
  // It peaks at kVisibleMu.
  EXPECT_GT(visible_wavelength_pdf(kVisibleMu), visible_wavelength_pdf(kVisibleMu - 1));
  EXPECT_GT(visible_wavelength_pdf(kVisibleMu), visible_wavelength_pdf(kVisibleMu + 1));
}

TEST(SpectralWavelengths, CdfIsTheIntegralOfThePdf) {
  EXPECT_EQ(visible_wavelength_cdf(kLambdaMin), 0);
  EXPECT_EQ(visible_wavelength_cdf(kLambdaMax), 1);
  for (double lambda = kLambdaMin + 10; lambda < kLambdaMax; lambda += 37) {
    EXPECT_NEAR(visible_wavelength_cdf(lambda),
                simpson(visible_wavelength_pdf, kLambdaMin, lambda, 2000), 1e-12)
        << lambda;
  }
}

TEST(SpectralWavelengths, InverseCdfInvertsTheCdf) {
  EXPECT_NEAR(sample_visible_wavelength(0), kLambdaMin, 1e-9);
  EXPECT_LE(sample_visible_wavelength(std::nextafter(1.0, 0.0)), kLambdaMax);
  EXPECT_NEAR(sample_visible_wavelength(std::nextafter(1.0, 0.0)), kLambdaMax, 1e-6);
  double previous = kLambdaMin;
  for (int i = 0; i <= 1000; ++i) {
    const double u = i / 1000.0 * std::nextafter(1.0, 0.0);
    const double lambda = sample_visible_wavelength(u);
    EXPECT_GE(lambda, previous);
    EXPECT_NEAR(visible_wavelength_cdf(lambda), u, 1e-12) << u;
    previous = lambda;
  }
  for (double lambda = kLambdaMin; lambda <= kLambdaMax; lambda += 4.7) {
    EXPECT_NEAR(sample_visible_wavelength(visible_wavelength_cdf(lambda)), lambda, 1e-8);
  }
}

TEST(SpectralWavelengths, SamplesFollowThePdf) {
  // Chi-square over 47 bins of 10 nm, expected counts from the CDF.
  constexpr int kBins = 47, kSamples = 1000000;
  std::vector<int> count(kBins, 0);
  Rng rng(8, 1);
  for (int n = 0; n < kSamples; ++n) {
    const double lambda = sample_visible_wavelength(rng.uniform());
    ++count[std::min(kBins - 1, static_cast<int>((lambda - kLambdaMin) / 10))];
  }
  double chi2 = 0;
  for (int b = 0; b < kBins; ++b) {
    const double p = visible_wavelength_cdf(kLambdaMin + 10 * (b + 1)) -
                     visible_wavelength_cdf(kLambdaMin + 10 * b);
    const double expected = kSamples * p;
    chi2 += (count[b] - expected) * (count[b] - expected) / expected;
  }
  EXPECT_LT(chi2, test::chi_square_critical(kBins - 1, 1e-4));
}

TEST(SpectralWavelengths, StratifiedEstimatorIsUnbiased) {
  // (1/N) Σ f(λ_i) / p(λ_i) over sample_wavelengths<N>(u) for a Gaussian with a closed-form
  // integral and for ȳ, whose integral is cie_y_integral() (the interpolated table's).
  const double sigma = 50, mu = 600;
  auto gaussian = [&](double l) { return std::exp(-(l - mu) * (l - mu) / (sigma * sigma)); };
  const double gaussian_integral =
      0.5 * std::sqrt(std::numbers::pi) * sigma *
      (std::erf((kLambdaMax - mu) / sigma) - std::erf((kLambdaMin - mu) / sigma));
  auto ybar = [](double l) { return cie_xyz_bar(l).y; };
  auto check = [](auto f, double truth) {
    constexpr int kN = 4;
    test::MeanVar estimate;
    Rng rng(8, 2);
    for (int n = 0; n < 200000; ++n) {
      const auto w = sample_wavelengths<kN>(rng.uniform());
      double sum = 0;
      for (int i = 0; i < kN; ++i) {
        EXPECT_NEAR(w.u[i] - w.u[0], double(i) / kN, 1e-15);
        sum += f(w.lambda[i]) / w.pdf[i];
      }
      estimate.add(sum / kN);
    }
    EXPECT_GT(estimate.std_error(), 0);
    EXPECT_LT(std::abs(estimate.mean - truth), 4 * estimate.std_error())
        << estimate.mean << " vs " << truth << " ± " << estimate.std_error();
  };
  check(gaussian, gaussian_integral);
  check(ybar, cie_y_integral());
}

// ---------------------------------------------------------------------------------------------
// CIE tables and colour spaces

TEST(SpectralCie, TablesMatchTheDataFiles) {
  // colord-data's values at a few knots, linear in between, 0 outside [360, 830].
  EXPECT_DOUBLE_EQ(cie_xyz_bar(555).y, 1.0);
  EXPECT_DOUBLE_EQ(cie_xyz_bar(600).x, 1.0622);
  EXPECT_DOUBLE_EQ(cie_xyz_bar(445).z, 1.7826);
  EXPECT_DOUBLE_EQ(cie_xyz_bar(360).x, 0.0001299);
  EXPECT_DOUBLE_EQ(cie_xyz_bar(557.5).y, 0.5 * (1.0 + 0.995));
  EXPECT_EQ(cie_xyz_bar(359.9).y, 0);
  EXPECT_EQ(cie_xyz_bar(830.1).y, 0);
  // D65 is relative: 1.0 at 560 nm and 1.09354 at 500 nm in the file.
  EXPECT_NEAR(d65_illuminant(500) / d65_illuminant(560), 1.09354, 1e-12);
  EXPECT_EQ(d65_illuminant(359), 0);
}

TEST(SpectralCie, LuminanceIntegral) {
  // The 1 nm CIE table gives ∫ȳ = 106.856895 nm; the 5 nm table linearly interpolated gives
  // 106.857028 (its trapezoid sum).
  EXPECT_NEAR(cie_y_integral(), 106.857028, 1e-6);
  double trapezoid = 0;
  for (int i = 0; i < 95; ++i)
    trapezoid += (i == 0 || i == 94 ? 2.5 : 5) * cie_xyz_bar(360 + 5 * i).y;
  EXPECT_NEAR(cie_y_integral(), trapezoid, 1e-10);
  // The constant 1 has luminance 1 and is near the equal-energy white (1/3, 1/3).
  const Vec3 xyz = emission_to_xyz(constant_spectrum(1));
  EXPECT_NEAR(xyz.y, 1.0, 1e-12);
  EXPECT_NEAR(chromaticity(xyz).x, 1.0 / 3, 3e-4);
  EXPECT_NEAR(chromaticity(xyz).y, 1.0 / 3, 3e-4);
}

TEST(SpectralCie, D65IsTheSrgbWhite) {
  SpectralCurve d65 = constant_spectrum(1);
  d65.illuminant = true;
  const Vec3 xyz = emission_to_xyz(d65);
  EXPECT_NEAR(xyz.y, 1.0, 1e-12);
  // CIE 15: D65 is at (0.31272, 0.32903) for the 2° observer.
  EXPECT_NEAR(chromaticity(xyz).x, 0.31272, 1e-4);
  EXPECT_NEAR(chromaticity(xyz).y, 0.32903, 1e-4);
  const Rgb rgb = emission_to_rgb(d65);
  EXPECT_LT(max_abs_diff(rgb, Rgb(1.0)), 1e-3) << rgb[0] << " " << rgb[1] << " " << rgb[2];
  // The same white through the reflectance path: a constant reflectance of 1 under D65.
  EXPECT_LT(max_abs_diff(reflectance_to_rgb(constant_spectrum(1)), Rgb(1.0)), 1e-3);
}

TEST(SpectralColor, SrgbMatrixMatchesIec61966) {
  // IEC 61966-2-1 prints the matrix rounded to 4 digits; nimbus derives it from the primaries.
  const double expected[3][3] = {
      {0.4124, 0.3576, 0.1805}, {0.2126, 0.7152, 0.0722}, {0.0193, 0.1192, 0.9505}};
  for (int j = 0; j < 3; ++j) {
    Rgb e(0.0);
    e[j] = 1;
    const Vec3 xyz = linear_srgb_to_xyz(e);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(xyz[i], expected[i][j], 6e-5) << i << " " << j;
  }
  const Vec3 white = linear_srgb_to_xyz(Rgb(1.0));
  EXPECT_NEAR(white.y, 1.0, 1e-14);
  EXPECT_NEAR(chromaticity(white).x, 0.3127, 1e-14);
  EXPECT_NEAR(chromaticity(white).y, 0.3290, 1e-14);
}

TEST(SpectralColor, XyzAndSrgbAreInverses) {
  Rng rng(8, 3);
  for (int n = 0; n < 1000; ++n) {
    const Rgb rgb({4 * rng.uniform() - 1, 4 * rng.uniform() - 1, 4 * rng.uniform() - 1});
    EXPECT_LT(max_abs_diff(xyz_to_linear_srgb(linear_srgb_to_xyz(rgb)), rgb), 1e-14);
    const Vec3 xyz = linear_srgb_to_xyz(rgb);
    const Vec3 back = linear_srgb_to_xyz(xyz_to_linear_srgb(xyz));
    EXPECT_LT(max_abs_diff(Rgb({back.x, back.y, back.z}), Rgb({xyz.x, xyz.y, xyz.z})), 1e-14);
  }
}

// ---------------------------------------------------------------------------------------------
// RGB upsampling

// Grey inputs become constant spectra exactly, whose projection is D65's white in sRGB: off
// (1, 1, 1) by up to 4.02e-4 (SpectralCie.D65IsTheSrgbWhite). Every other colour is polished by
// Gauss–Newton after the table lookup; measured: largest error 1.0e-13 over 4·10⁵ uniform
// colours (2.2e-13 relative to max(rgb) for dark ones), against 2.0e-3 from the table alone.
constexpr double kPolished = 1e-12;
constexpr double kGreyWhite = 4.1e-4;

bool is_grey(const Rgb& c) {
  return c[0] == c[1] && c[1] == c[2];
}

TEST(SpectralUpsampling, AlbedoRoundTrip) {
  for (const Rgb& rgb : grid_colours(11, 1)) {
    const double error = max_abs_diff(reflectance_to_rgb(rgb_albedo_spectrum(rgb)), rgb);
    EXPECT_LT(error, is_grey(rgb) ? kGreyWhite * rgb.max() + 1e-15 : kPolished)
        << rgb[0] << " " << rgb[1] << " " << rgb[2];
  }
  Rng rng(8, 4);
  for (int n = 0; n < 20000; ++n) {
    const Rgb rgb({rng.uniform(), rng.uniform(), rng.uniform()});
    const double error = max_abs_diff(reflectance_to_rgb(rgb_albedo_spectrum(rgb)), rgb);
    EXPECT_LT(error, kPolished) << rgb[0] << " " << rgb[1] << " " << rgb[2];
  }
  // Bright colours next to grey, the table's worst case (1.3e-3 before polishing).
  for (const Rgb& rgb : {Rgb({0.9995, 0.999, 0.99}), Rgb({0.999, 0.998, 0.997})})
    EXPECT_LT(max_abs_diff(reflectance_to_rgb(rgb_albedo_spectrum(rgb)), rgb), kPolished);
}

TEST(SpectralUpsampling, DarkColoursKeepTheirRelativeAccuracy) {
  // Below the table's z range the curve is scaled, so the error stays relative to max(rgb).
  Rng rng(8, 5);
  for (int n = 0; n < 20000; ++n) {
    Rgb rgb({rng.uniform(), rng.uniform(), rng.uniform()});
    rgb = rgb * (std::pow(10.0, -6 * rng.uniform()) / rgb.max());
    const double error = max_abs_diff(reflectance_to_rgb(rgb_albedo_spectrum(rgb)), rgb);
    EXPECT_LT(error / rgb.max(), kPolished) << rgb[0] << " " << rgb[1] << " " << rgb[2];
  }
}

TEST(SpectralUpsampling, GreyIsConstant) {
  for (double v : {0.0, 0.18, 0.5, 1.0}) {
    const SpectralCurve s = rgb_albedo_spectrum(Rgb(v));
    EXPECT_EQ(s.type, SpectralCurve::Type::Constant);
    EXPECT_EQ(s(400), v);
    EXPECT_EQ(s(700), v);
  }
  const SpectralCurve u = rgb_unbounded_spectrum(Rgb(7.5));
  EXPECT_EQ(u.type, SpectralCurve::Type::Constant);
  EXPECT_EQ(u(555), 7.5);
  const SpectralCurve e = rgb_illuminant_spectrum(Rgb(2.0));
  EXPECT_EQ(e.type, SpectralCurve::Type::Constant);
  EXPECT_DOUBLE_EQ(e(500), 2 * d65_illuminant(500));
}

TEST(SpectralUpsampling, UnboundedAndIlluminantRoundTrips) {
  // The curve is 2·max(rgb) times an albedo curve with largest component 1/2, so its error scales
  // with max(rgb).
  for (const Rgb& rgb : grid_colours(11, 10)) {
    const double tolerance = (is_grey(rgb) ? kGreyWhite : kPolished) * rgb.max() + 1e-300;
    const Rgb unbounded = reflectance_to_rgb(rgb_unbounded_spectrum(rgb));
    EXPECT_LE(max_abs_diff(unbounded, rgb), tolerance) << rgb[0] << " " << rgb[1] << " " << rgb[2];
    // Emission of grey times D65 is exactly the sRGB white of the data.
    const Rgb emitted = emission_to_rgb(rgb_illuminant_spectrum(rgb));
    EXPECT_LE(max_abs_diff(emitted, rgb), tolerance) << rgb[0] << " " << rgb[1] << " " << rgb[2];
  }
}

TEST(SpectralUpsampling, IlluminantIsUnboundedTimesD65) {
  const Rgb rgb({0.2, 3.0, 1.1});
  const SpectralCurve u = rgb_unbounded_spectrum(rgb), e = rgb_illuminant_spectrum(rgb);
  EXPECT_TRUE(e.illuminant);
  for (double lambda = 360; lambda <= 830; lambda += 10) {
    EXPECT_DOUBLE_EQ(e(lambda), u(lambda) * d65_illuminant(lambda));
  }
  // Emission of D65 · s is what reflectance_to_rgb sees for s.
  EXPECT_LT(max_abs_diff(emission_to_rgb(e), reflectance_to_rgb(u)), 1e-12);
}

TEST(SpectralUpsampling, AlbedoCurvesStayInTheUnitInterval) {
  for (const Rgb& rgb : grid_colours(11, 1)) {
    const SpectralCurve s = rgb_albedo_spectrum(rgb);
    for (double lambda = 300; lambda <= 900; lambda += 0.5) {
      const double v = s(lambda);
      ASSERT_GE(v, 0) << rgb[0] << " " << rgb[1] << " " << rgb[2] << " at " << lambda;
      ASSERT_LE(v, 1) << rgb[0] << " " << rgb[1] << " " << rgb[2] << " at " << lambda;
    }
  }
  // Inputs outside [0, 1] are clamped into it.
  const SpectralCurve s = rgb_albedo_spectrum(Rgb({1.5, -0.2, 0.3}));
  for (double lambda = 300; lambda <= 900; lambda += 0.5) {
    EXPECT_GE(s(lambda), 0);
    EXPECT_LE(s(lambda), 1);
  }
}

// ---------------------------------------------------------------------------------------------
// Curves: range, piecewise linear, blackbody

// range(lo, hi) must contain every value in [lo, hi]; where `exact`, it must also be reached by
// dense samples (to within what a 0.01 nm grid can miss near an interior extreme).
void expect_range_bounds(const SpectralCurve& s, bool exact, const char* what) {
  const double intervals[][2] = {{360, 830}, {300, 900}, {400, 401},  {512.3, 512.3},
                                 {540, 610}, {355, 365}, {700, 1200}, {200, 420}};
  for (const auto& [lo, hi] : intervals) {
    const auto [bound_lo, bound_hi] = s.range(lo, hi);
    double seen_lo = INFINITY, seen_hi = -INFINITY;
    const int n = std::max(1, static_cast<int>((hi - lo) / 0.01));
    for (int i = 0; i <= n; ++i) {
      const double v = s(lo + (hi - lo) * i / n);
      seen_lo = std::min(seen_lo, v);
      seen_hi = std::max(seen_hi, v);
    }
    const double slack = 1e-12 * std::max(1.0, std::abs(bound_hi));
    EXPECT_LE(bound_lo, seen_lo + slack) << what << " [" << lo << ", " << hi << "]";
    EXPECT_GE(bound_hi, seen_hi - slack) << what << " [" << lo << ", " << hi << "]";
    if (exact) {
      const double tight = 1e-6 * std::max(1.0, std::abs(bound_hi));
      EXPECT_NEAR(bound_lo, seen_lo, tight) << what << " [" << lo << ", " << hi << "]";
      EXPECT_NEAR(bound_hi, seen_hi, tight) << what << " [" << lo << ", " << hi << "]";
    }
  }
}

TEST(SpectralCurve, RangeBoundsEveryType) {
  expect_range_bounds(constant_spectrum(0.7), true, "constant");
  expect_range_bounds(constant_spectrum(-2), true, "negative constant");
  for (const Rgb& rgb : {Rgb({0.9, 0.2, 0.1}), Rgb({0.1, 0.8, 0.3}), Rgb({0.3, 0.2, 0.95}),
                         Rgb({0.05, 0.0, 0.04}), Rgb({1.0, 1.0, 0.0})}) {
    expect_range_bounds(rgb_albedo_spectrum(rgb), true, "albedo");
    expect_range_bounds(rgb_unbounded_spectrum(rgb * 6), true, "unbounded");
    expect_range_bounds(rgb_illuminant_spectrum(rgb * 3), false, "illuminant");
  }
  SpectralCurve vertex;  // a sigmoid whose quadratic peaks at 512.3 nm
  vertex.type = SpectralCurve::Type::Sigmoid;
  vertex.c0 = -1e-3;
  vertex.c1 = 2e-3 * 512.3;
  vertex.c2 = -1e-3 * 512.3 * 512.3 + 2;
  expect_range_bounds(vertex, true, "sigmoid vertex");
  const SpectralCurve pwl =
      piecewise_linear_spectrum({{380, 0.2}, {450, 0.9}, {512.3, -0.4}, {700, 0.5}});
  expect_range_bounds(pwl, true, "piecewise linear");
  SpectralCurve pwl_lit = pwl;
  pwl_lit.illuminant = true;
  expect_range_bounds(pwl_lit, false, "piecewise linear illuminant");
  for (double kelvin : {1500.0, 3000.0, 5000.0, 6504.0, 12000.0}) {
    expect_range_bounds(blackbody_spectrum(kelvin, 2), true, "blackbody");
  }
  SpectralCurve d65 = constant_spectrum(1.5);
  d65.illuminant = true;
  expect_range_bounds(d65, true, "D65");
}

TEST(SpectralCurve, PiecewiseLinearInterpolatesAndHoldsItsEnds) {
  const SpectralCurve s = piecewise_linear_spectrum({{400, 1}, {500, 3}, {600, 2}});
  EXPECT_EQ(s(300), 1);
  EXPECT_EQ(s(400), 1);
  EXPECT_DOUBLE_EQ(s(450), 2);
  EXPECT_EQ(s(500), 3);
  EXPECT_DOUBLE_EQ(s(575), 2.25);
  EXPECT_EQ(s(600), 2);
  EXPECT_EQ(s(900), 2);
  const SpectralCurve one = piecewise_linear_spectrum({{550, 0.4}});
  EXPECT_EQ(one(300), 0.4);
  EXPECT_EQ(one(550), 0.4);
  EXPECT_EQ(one(800), 0.4);
  EXPECT_THROW(piecewise_linear_spectrum({}), std::invalid_argument);
  EXPECT_THROW(piecewise_linear_spectrum({{500, 1}, {500, 2}}), std::invalid_argument);
  EXPECT_THROW(piecewise_linear_spectrum({{500, 1}, {400, 2}}), std::invalid_argument);
  EXPECT_THROW(piecewise_linear_spectrum({{500, NAN}}), std::invalid_argument);
}

TEST(SpectralCurve, BlackbodyIsNormalisedToItsLuminance) {
  for (double kelvin : {1000.0, 2856.0, 5000.0, 6504.0, 20000.0}) {
    for (double scale : {1.0, 0.25, 40.0}) {
      EXPECT_NEAR(emission_to_xyz(blackbody_spectrum(kelvin, scale)).y, scale, 1e-12 * scale);
    }
  }
  // Chromaticities on the Planckian locus: 2856 K is CIE illuminant A (0.44757, 0.40745), and
  // 6500 K is at (0.3135, 0.3236) (Wyszecki and Stiles, table 1(3.11)).
  const Vec3 a = chromaticity(emission_to_xyz(blackbody_spectrum(2856, 1)));
  EXPECT_NEAR(a.x, 0.44757, 2e-4);
  EXPECT_NEAR(a.y, 0.40745, 2e-4);
  const Vec3 d = chromaticity(emission_to_xyz(blackbody_spectrum(6500, 1)));
  EXPECT_NEAR(d.x, 0.3135, 2e-4);
  EXPECT_NEAR(d.y, 0.3236, 2e-4);
  EXPECT_THROW(blackbody_spectrum(0, 1), std::invalid_argument);
  EXPECT_THROW(blackbody_spectrum(5, 1), std::invalid_argument);  // nothing visible
}

TEST(SpectralCurve, BlackbodyPeaksAtWiensWavelength) {
  // Wien's displacement constant b = 2.897771955e-3 m·K (CODATA 2018).
  for (double kelvin : {2000.0, 3000.0, 5000.0, 5778.0, 9000.0}) {
    const SpectralCurve s = blackbody_spectrum(kelvin, 1);
    double best = 0, best_lambda = 0;
    for (double lambda = 200; lambda <= 2000; lambda += 0.01) {
      if (s(lambda) > best) best = s(lambda), best_lambda = lambda;
    }
    EXPECT_NEAR(best_lambda, 2.897771955e6 / kelvin, 0.02) << kelvin;
  }
}

}  // namespace spectral_test
}  // namespace nimbus
