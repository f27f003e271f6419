#include "nimbus/media/cloud_density.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>

#include "nimbus/math/rng.h"

namespace nimbus {
namespace cloud_density_test {

Vec3 random_point(Rng& rng, double r) {
  return {r * (2 * rng.uniform() - 1), r * (2 * rng.uniform() - 1), r * (2 * rng.uniform() - 1)};
}

TEST(CloudDensity, ZeroWhereFIsNotPositiveAndWithinUnitInterval) {
  const CloudNoise cloud = make_cloud_noise({});
  Rng rng(1);
  for (int i = 0; i < 20000; ++i) {
    const Vec3 x = random_point(rng, 1.5);
    const double F = 1 - dot(x, x);
    const double d = cloud_density(cloud, x, F);
    if (F <= 0) {
      EXPECT_EQ(d, 0.0);
    }
    EXPECT_GE(d, 0.0);
    EXPECT_LE(d, 1.0);
  }
  EXPECT_EQ(cloud_density(cloud, {0.1, 0.2, 0.3}, 0.0), 0.0);
  EXPECT_EQ(cloud_density(cloud, {0.1, 0.2, 0.3}, -5.0), 0.0);
}

// The density with the noise computed afresh: a call at another point first replaces the
// thread's last point, which cloud_density reuses at the same point of the same cloud.
double fresh_density(const CloudNoise& cloud, const Vec3& x, double F) {
  cloud_density(cloud, x + Vec3{1, 0, 0}, F);
  return cloud_density(cloud, x, F);
}

TEST(CloudDensity, TheNoiseReusedAtAPointIsThatCloudsOwn) {
  Rng rng(7);
  for (int i = 0; i < 500; ++i) {
    // Two clouds at one point, one after another, as overlapping puffs of two media are looked
    // up; then a cloud made where the first was (a scene reloaded): none gets another's noise.
    const Vec3 x = random_point(rng, 1);
    const double F1 = 0.1 * rng.uniform(), F2 = 0.1 * rng.uniform();
    auto a = std::make_unique<CloudNoise>(make_cloud_noise({.amplitude = 0.8, .seed = 1}));
    const CloudNoise b = make_cloud_noise({.amplitude = 0.8, .seed = 2});
    const double a1 = fresh_density(*a, x, F1), a2 = fresh_density(*a, x, F2);
    const double b1 = fresh_density(b, x, F1);
    EXPECT_EQ(cloud_density(*a, x, F1), a1);
    EXPECT_EQ(cloud_density(b, x, F1), b1);
    EXPECT_EQ(cloud_density(*a, x, F2), a2);
    *a = make_cloud_noise({.amplitude = 0.8, .seed = 2});
    EXPECT_EQ(cloud_density(*a, x, F1), b1);
  }
}

TEST(CloudDensity, NonDecreasingInF) {
  const CloudNoise cloud = make_cloud_noise({.octaves = 4, .amplitude = 0.7, .seed = 3});
  Rng rng(2);
  int increases = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 x = random_point(rng, 2);
    double prev = 0;
    for (int k = 0; k <= 60; ++k) {
      const double d = cloud_density(cloud, x, -0.2 + 1.4 * k / 60);
      EXPECT_GE(d, prev);
      increases += d > prev;
      prev = d;
    }
  }
  EXPECT_GT(increases, 0);  // not trivially constant
}

TEST(CloudDensity, RangeContainsSampledDensities) {
  // Random F intervals, random points, random F inside the interval: the density must lie in
  // cloud_density_range(F_lo, F_hi). Also the sampled densities must reach into the interior of
  // [0, 1] (the check is not vacuous) and the range must be ordered.
  for (const CloudParams params :
       {CloudParams{},
        CloudParams{.octaves = 2, .frequency = 5, .amplitude = 0.3, .seed = 9, .edge = 0.5}}) {
    const CloudNoise cloud = make_cloud_noise(params);
    Rng rng(params.seed, 4);
    int strictly_inside = 0;
    for (int i = 0; i < 50000; ++i) {
      double F_lo = -0.5 + 2 * rng.uniform(), F_hi = -0.5 + 2 * rng.uniform();
      if (F_lo > F_hi) std::swap(F_lo, F_hi);
      const auto [lo, hi] = cloud_density_range(F_lo, F_hi, params);
      ASSERT_LE(lo, hi);
      const double F = F_lo + (F_hi - F_lo) * rng.uniform();
      const double d = cloud_density(cloud, random_point(rng, 3), F);
      EXPECT_GE(d, lo) << F_lo << " " << F_hi << " " << F;
      EXPECT_LE(d, hi) << F_lo << " " << F_hi << " " << F;
      strictly_inside += d > 0 && d < 1;
    }
    EXPECT_GT(strictly_inside, 1000);
  }
}

TEST(CloudDensity, RangeIsTightAtTheEnds) {
  const CloudParams p{};
  // Outside the object, nothing; where the profile is full (F >= edge), full density.
  EXPECT_EQ(cloud_density_range(-2, 0, p), std::make_pair(0.0, 0.0));
  EXPECT_EQ(cloud_density_range(p.edge, 5, p), std::make_pair(1.0, 1.0));
  // Near the surface the noise can erode everything.
  EXPECT_EQ(cloud_density_range(0.01, 0.1, p).first, 0.0);
}

TEST(CloudDensity, ExactlyOneFromTheEdgeOnAndBelowOneJustInside) {
  // d = 1 wherever F >= edge (cloud_density returns it without the noise); just below the edge
  // the noise still erodes some points, so that shortcut reaches no further.
  const CloudParams p{.octaves = 4, .frequency = 3, .amplitude = 0.6, .seed = 5, .edge = 0.4};
  const CloudNoise cloud = make_cloud_noise(p);
  Rng rng(11);
  int eroded_below = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3 x = random_point(rng, 2);
    EXPECT_EQ(cloud_density(cloud, x, p.edge + 2 * rng.uniform()), 1.0);
    eroded_below += cloud_density(cloud, x, 0.97 * p.edge) < 1;
  }
  EXPECT_GT(eroded_below, 1000);
}

TEST(CloudDensity, ErodedEdgeHasHolesAndDenseCore) {
  // On the unit sphere with F = 1 − |x|², amplitude 0.6: between radii 0.75 and 0.95 some
  // points are empty and some are not (billowy edge with holes); near the centre all are dense.
  const CloudNoise cloud = make_cloud_noise({});
  Rng rng(7);
  int empty_shell = 0, full_shell = 0, thin_core = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3 dir = normalize(random_point(rng, 1) + Vec3{1e-9, 0, 0});
    const double r_shell = 0.75 + 0.2 * rng.uniform(), r_core = 0.2 * rng.uniform();
    const double d_shell = cloud_density(cloud, r_shell * dir, 1 - r_shell * r_shell);
    empty_shell += d_shell == 0;
    full_shell += d_shell > 0.05;
    thin_core += cloud_density(cloud, r_core * dir, 1 - r_core * r_core) < 0.5;
  }
  EXPECT_GT(empty_shell, 2000);
  EXPECT_GT(full_shell, 2000);
  EXPECT_EQ(thin_core, 0);
}

}  // namespace cloud_density_test
}  // namespace nimbus
