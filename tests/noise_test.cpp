#include "nimbus/media/noise.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "nimbus/math/rng.h"

namespace nimbus {
namespace noise_test {

Vec3 random_point(Rng& rng, double r) {
  return {r * (2 * rng.uniform() - 1), r * (2 * rng.uniform() - 1), r * (2 * rng.uniform() - 1)};
}

TEST(Noise, BoundHoldsOnAMillionPoints) {
  // |noise| <= √3/2 (proof in noise.h). The maximum over 10⁶ points must respect it, and must come
  // reasonably close (otherwise the bound would be needlessly loose for majorants).
  for (uint64_t seed : {1u, 2u}) {
    const Noise n = make_noise(seed);
    Rng rng(seed, 9);
    double max_abs = 0;
    for (int i = 0; i < 1000000; ++i)
      max_abs = std::max(max_abs, std::abs(noise(n, random_point(rng, 300))));
    EXPECT_LE(max_abs, kNoiseBound) << seed;
    EXPECT_GT(max_abs, 0.6 * kNoiseBound) << seed;
  }
}

// Issue 29: a cloud of frequency 1e308 made NaN samples, and past 2^63 the lattice cell had no
// int64 (undefined behaviour). The lattice repeats every 256 cells, and far coordinates are
// reduced into one period exactly: the noise there is the noise of the reduced point, finite
// and bounded, and a point that is not finite reads the origin's cell.
TEST(Noise, FarCoordinatesAreReducedIntoOnePeriod) {
  const Noise n = make_noise(3);
  Rng rng(5, 1);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 far = random_point(rng, 1e200);
    const Vec3 reduced{std::fmod(far.x, 256.0), std::fmod(far.y, 256.0), std::fmod(far.z, 256.0)};
    EXPECT_EQ(noise(n, far), noise(n, reduced)) << i;
    EXPECT_LE(std::abs(noise(n, far)), kNoiseBound);
  }
  // Below 2^52 nothing changes: one period on, the same value.
  const Vec3 p{0x1p51 + 0.25, -17.5, 3.75};
  EXPECT_EQ(noise(n, p), noise(n, p + Vec3{256, 0, 0}));
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(std::isfinite(noise(n, {inf, -inf, 1.5})));
}

TEST(Noise, FadeWeightsSatisfyTheBoundLemma) {
  // The proof's lemma: h(t) = t² + S(t)(1 − 2t) <= t(1 − t) <= 1/4 on [0, 1].
  for (int i = 0; i <= 10000; ++i) {
    const double t = i / 10000.0;
    const double S = t * t * t * (t * (t * 6 - 15) + 10);
    const double h = t * t + S * (1 - 2 * t);
    EXPECT_LE(h, t * (1 - t) + 1e-15) << t;
  }
}

TEST(Noise, ZeroOnTheLatticeAndDeterministic) {
  const Noise a = make_noise(5), b = make_noise(5), c = make_noise(6);
  for (int i = -3; i <= 3; ++i)
    for (int j = -3; j <= 3; ++j)
      EXPECT_EQ(noise(a, Vec3{double(i), double(j), double(i * j)}), 0.0);
  Rng rng(3);
  int differ = 0;
  for (int k = 0; k < 100; ++k) {
    const Vec3 x = random_point(rng, 50);
    EXPECT_EQ(noise(a, x), noise(b, x));
    differ += noise(a, x) != noise(c, x);
  }
  EXPECT_GT(differ, 90);
}

TEST(Noise, IsContinuousAcrossCellFaces) {
  const Noise n = make_noise(8);
  Rng rng(4);
  for (int k = 0; k < 1000; ++k) {
    Vec3 x = random_point(rng, 20);
    x.y = std::floor(x.y);
    const double h = 1e-9;
    EXPECT_NEAR(noise(n, x + Vec3{0, h, 0}), noise(n, x - Vec3{0, h, 0}), 1e-8);
  }
}

TEST(Noise, FbmBoundIsSumOfOctaveBounds) {
  EXPECT_EQ(fbm_bound(0), 0.0);
  EXPECT_DOUBLE_EQ(fbm_bound(1), kNoiseBound);
  EXPECT_DOUBLE_EQ(fbm_bound(4), kNoiseBound * (1 + 0.5 + 0.25 + 0.125));
  const Noise n = make_noise(3);
  Rng rng(5);
  for (int octaves : {1, 3, 6}) {
    double max_abs = 0;
    for (int i = 0; i < 100000; ++i)
      max_abs = std::max(max_abs, std::abs(fbm(n, random_point(rng, 100), octaves)));
    EXPECT_LE(max_abs, fbm_bound(octaves)) << octaves;
    EXPECT_GT(max_abs, 0.4 * fbm_bound(octaves)) << octaves;
  }
}

}  // namespace noise_test
}  // namespace nimbus
