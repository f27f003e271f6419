#include "nimbus/media/phase.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "nimbus/math/rng.h"
#include "support/stats.h"

namespace nimbus {
namespace phase_test {

constexpr double kPi = std::numbers::pi;

using test::simpson;

TEST(Phase, IsotropicIsOneOverFourPi) {
  for (double c : {-1.0, -0.3, 0.0, 0.8, 1.0}) EXPECT_DOUBLE_EQ(hg_phase(c, 0), kInv4Pi);
  EXPECT_DOUBLE_EQ(Phase{}.eval({0, 0, 1}, {1, 0, 0}), kInv4Pi);
}

TEST(Phase, PositiveGScattersForward) {
  // cos θ = dot of propagation directions: with g > 0, going on straight is likelier than
  // turning back.
  EXPECT_GT(hg_phase(1, 0.5), hg_phase(-1, 0.5));
  EXPECT_LT(hg_phase(1, -0.5), hg_phase(-1, -0.5));
  const Phase p{0.8};
  EXPECT_GT(p.eval({0, 0, 1}, {0, 0, 1}), p.eval({0, 0, 1}, {0, 0, -1}));
}

TEST(Phase, IntegratesToOne) {
  // 2π ∫_{-1}^{1} p(c) dc. The integrand is smooth and analytic on [-1, 1] for |g| <= 0.95, so
  // Simpson with 2·10⁵ intervals is accurate far beyond 1e-9.
  for (double g : {-0.95, -0.7, -0.2, 0.0, 0.3, 0.6, 0.9, 0.95}) {
    const double total = 2 * kPi * simpson([g](double c) { return hg_phase(c, g); }, -1, 1, 200000);
    EXPECT_NEAR(total, 1.0, 1e-9) << "g = " << g;
  }
}

TEST(Phase, CosineInversionIsStableAndMonotone) {
  // Endpoints map to ±1 for every g, tiny g agrees with the isotropic map 2u − 1, and the map
  // is non-decreasing in u.
  for (double g : {-0.99, -0.5, -1e-12, 0.0, 1e-12, 0.5, 0.99}) {
    EXPECT_NEAR(sample_hg_cos_theta(g, 0.0), -1, 1e-12) << g;
    EXPECT_NEAR(sample_hg_cos_theta(g, 1.0), 1, 1e-12) << g;
    double prev = -1;
    for (int i = 0; i <= 1000; ++i) {
      const double c = sample_hg_cos_theta(g, i / 1000.0);
      EXPECT_GE(c, prev) << g << " " << i;
      prev = c;
    }
  }
  for (double u : {0.1, 0.37, 0.5, 0.9})
    EXPECT_NEAR(sample_hg_cos_theta(1e-10, u), 2 * u - 1, 1e-9);
}

// Issue 16: g = ±0.99999999 and ±0.9999999999999999 passed validation and wrote NaN pixels:
// 1 + g² − 2 g cos θ cancelled to 0 or below at cos θ = ±1. Over the whole accepted range
// (−1, 1) the density is finite and positive, matches (1 − g²)/(4π (1 − g)³) exactly at its peak,
// and the sampler returns cosines in [−1, 1] whose density is finite.
TEST(Phase, StableAtTheEndsOfTheAcceptedRange) {
  for (double g : {0.99999999, 0.9999999999999999, 1 - 1e-12, -0.99999999, -0.9999999999999999}) {
    const double peak = g > 0 ? 1.0 : -1.0;
    const double expected = kInv4Pi * (1 + std::abs(g)) / std::pow(1 - std::abs(g), 2);
    EXPECT_NEAR(hg_phase(peak, g) / expected, 1, 1e-12) << g;
    for (double c : {-1.0, -0.999999, -0.5, 0.0, 0.5, 0.999999, 1.0}) {
      const double p = hg_phase(c, g);
      EXPECT_TRUE(std::isfinite(p) && p > 0) << "g " << g << ", cos " << c << ": " << p;
    }
    Rng rng(21);
    for (int i = 0; i < 10000; ++i) {
      const double u =
          i < 3 ? std::array<double, 3>{0.0, 1e-300, std::nextafter(1.0, 0.0)}[i] : rng.uniform();
      const double c = sample_hg_cos_theta(g, u);
      ASSERT_TRUE(c >= -1 && c <= 1) << "g " << g << ", u " << u << ": " << c;
      const double p = hg_phase(c, g);
      ASSERT_TRUE(std::isfinite(p) && p > 0) << "g " << g << ", u " << u;
    }
  }
}

TEST(Phase, SampledDirectionsAreUnit) {
  Rng rng(11);
  const Vec3 dir = normalize(Vec3{0.3, -0.5, 0.8});
  for (int i = 0; i < 1000; ++i) {
    const Vec3 w = sample_hg(dir, 0.6, rng.uniform(), rng.uniform());
    EXPECT_NEAR(length(w), 1.0, 1e-12);
  }
}

// Chi-square goodness of fit of sample_hg against hg_phase, binned over (cos θ, φ) measured in
// an independent frame around a tilted `dir`. Expected bin probabilities come from quadrature of
// hg_phase, not from the sampler's inverse CDF.
TEST(Phase, SamplingMatchesDensityChiSquare) {
  constexpr int kCosBins = 32, kPhiBins = 8, kSamples = 200000;
  const Vec3 dir = normalize(Vec3{0.3, -0.5, 0.8});
  Vec3 e1 = normalize(cross(dir, Vec3{1, 0, 0}));
  const Vec3 e2 = cross(dir, e1);
  const double critical = test::chi_square_critical(kCosBins * kPhiBins - 1, 1e-4);
  for (double g : {-0.7, 0.0, 0.3, 0.9}) {
    std::vector<double> expected(kCosBins * kPhiBins);
    for (int i = 0; i < kCosBins; ++i) {
      const double c0 = -1 + 2.0 * i / kCosBins, c1 = -1 + 2.0 * (i + 1) / kCosBins;
      const double p = 2 * kPi * simpson([g](double c) { return hg_phase(c, g); }, c0, c1, 200);
      for (int j = 0; j < kPhiBins; ++j) expected[i * kPhiBins + j] = kSamples * p / kPhiBins;
    }
    std::vector<int> count(expected.size(), 0);
    Rng rng(1234, static_cast<uint64_t>(100 * (g + 1)));
    for (int n = 0; n < kSamples; ++n) {
      const Vec3 w = sample_hg(dir, g, rng.uniform(), rng.uniform());
      const double c = std::clamp(dot(w, dir), -1.0, 1.0);
      const double phi = std::atan2(dot(w, e2), dot(w, e1)) + kPi;
      const int i = std::min(kCosBins - 1, static_cast<int>((c + 1) / 2 * kCosBins));
      const int j = std::min(kPhiBins - 1, static_cast<int>(phi / (2 * kPi) * kPhiBins));
      ++count[i * kPhiBins + j];
    }
    double chi2 = 0;
    for (size_t b = 0; b < expected.size(); ++b) {
      ASSERT_GE(expected[b], 5.0) << "bin " << b << " too small for chi-square, g = " << g;
      chi2 += (count[b] - expected[b]) * (count[b] - expected[b]) / expected[b];
    }
    EXPECT_LT(chi2, critical) << "g = " << g;
  }
}

TEST(Phase, MeanCosineIsG) {
  const Vec3 dir{0, 0, 1};
  for (double g : {-0.7, 0.0, 0.3, 0.9}) {
    Rng rng(77, static_cast<uint64_t>(100 * (g + 1)));
    test::MeanVar cosine;
    for (int n = 0; n < 100000; ++n)
      cosine.add(dot(sample_hg(dir, g, rng.uniform(), rng.uniform()), dir));
    EXPECT_NEAR(cosine.mean, g, 4 * cosine.std_error()) << "g = " << g;
  }
}

}  // namespace phase_test
}  // namespace nimbus
