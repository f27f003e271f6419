#include "nimbus/math/interval.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "nimbus/math/rng.h"

namespace nimbus {
namespace interval_test {

constexpr double kInf = std::numeric_limits<double>::infinity();

double random_value(Rng& rng) {
  // Mixed magnitudes, both signs, some exact zeros.
  const double u = rng.uniform();
  if (u < 0.05) return 0.0;
  return (2 * rng.uniform() - 1) * std::pow(10.0, 12 * rng.uniform() - 6);
}

Interval random_interval(Rng& rng) {
  double a = random_value(rng), b = random_value(rng);
  if (rng.uniform() < 0.1) b = a;
  return {std::min(a, b), std::max(a, b)};
}

double inside(Rng& rng, Interval x) {
  const double u = rng.uniform();
  if (u < 0.1) return x.lo;
  if (u < 0.2) return x.hi;
  return std::clamp(x.lo + (x.hi - x.lo) * rng.uniform(), x.lo, x.hi);
}

TEST(Interval, NextUpDownAgreeWithNextafter) {
  const double specials[] = {0.0,
                             -0.0,
                             1.0,
                             -1.0,
                             std::numeric_limits<double>::denorm_min(),
                             -std::numeric_limits<double>::denorm_min(),
                             std::numeric_limits<double>::min(),
                             std::numeric_limits<double>::max(),
                             -std::numeric_limits<double>::max(),
                             kInf,
                             -kInf};
  for (double x : specials) {
    EXPECT_EQ(next_down(x), std::nextafter(x, -kInf)) << x;
    EXPECT_EQ(next_up(x), std::nextafter(x, kInf)) << x;
  }
  Rng rng(5);
  for (int i = 0; i < 10000; ++i) {
    const double x = random_value(rng);
    ASSERT_EQ(next_down(x), std::nextafter(x, -kInf)) << x;
    ASSERT_EQ(next_up(x), std::nextafter(x, kInf)) << x;
  }
  EXPECT_TRUE(std::isnan(next_down(std::nan(""))));
}

TEST(Interval, EveryOperationEnclosesItsPointValues) {
  Rng rng(6);
  for (int trial = 0; trial < 20000; ++trial) {
    const Interval x = random_interval(rng), y = random_interval(rng);
    const double s = random_value(rng);
    for (int k = 0; k < 5; ++k) {
      const double a = inside(rng, x), b = inside(rng, y);
      ASSERT_TRUE((x + y).contains(a + b));
      ASSERT_TRUE((x - y).contains(a - b));
      ASSERT_TRUE((x * y).contains(a * b));
      ASSERT_TRUE((s * x).contains(s * a));
      ASSERT_TRUE((-x).contains(-a));
      ASSERT_TRUE(square(x).contains(a * a));
      ASSERT_TRUE(cube(x).contains(a * a * a));
      const double p = std::max(a, 0.0);
      ASSERT_TRUE(positive_cube(x).contains(p * p * p));
      ASSERT_TRUE(max(x, y).contains(std::max(a, b)));
      ASSERT_TRUE(min(x, y).contains(std::min(a, b)));
    }
  }
}

TEST(Interval, BoundsAreRoundedOutward) {
  // 0.1 · 0.3 is inexact in binary: the rounded product must lie strictly inside.
  const Interval p = Interval::point(0.1) * Interval::point(0.3);
  EXPECT_LT(p.lo, 0.1 * 0.3);
  EXPECT_GT(p.hi, 0.1 * 0.3);
  const Interval s = Interval::point(0.1) + Interval::point(0.2);
  EXPECT_LT(s.lo, 0.1 + 0.2);
  EXPECT_GT(s.hi, 0.1 + 0.2);
  // The cube's two roundings are each covered: the exact 1.1³ lies inside (long double check).
  const Interval c = cube(Interval::point(1.1));
  const long double exact = static_cast<long double>(1.1) * 1.1L * 1.1L;
  EXPECT_LE(static_cast<long double>(c.lo), exact);
  EXPECT_GE(static_cast<long double>(c.hi), exact);
  // max(x, 0)³ of a non-positive interval is exactly 0.
  const Interval z = positive_cube(Interval{-2.0, -1.0});
  EXPECT_EQ(z.lo, 0.0);
  EXPECT_EQ(z.hi, 0.0);
}

TEST(Interval, SquareOfAStraddlingIntervalStartsAtZero) {
  const Interval s = square({-2.0, 3.0});
  EXPECT_EQ(s.lo, 0.0);
  EXPECT_GE(s.hi, 9.0);
  EXPECT_LT(s.hi, 9.0 + 1e-14);
  EXPECT_TRUE((Interval{-kInf, 1.0} + Interval{0.0, 1.0}).contains(-1e300));
}

TEST(Interval, ExcludesZero) {
  EXPECT_TRUE((Interval{1e-300, 1.0}).excludes_zero());
  EXPECT_TRUE((Interval{-1.0, -1e-300}).excludes_zero());
  EXPECT_FALSE((Interval{0.0, 1.0}).excludes_zero());
  EXPECT_FALSE((Interval{-1.0, 0.0}).excludes_zero());
}

}  // namespace interval_test
}  // namespace nimbus
