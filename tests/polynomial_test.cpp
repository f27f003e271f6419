#include "nimbus/math/polynomial.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "nimbus/math/rng.h"

namespace nimbus {
namespace polynomial_test {

// Coefficients (increasing powers) of scale · Π (x − r_i).
std::vector<double> from_roots(const std::vector<double>& roots, double scale = 1.0) {
  std::vector<double> c{scale};
  for (double r : roots) {
    std::vector<double> next(c.size() + 1, 0.0);
    for (size_t i = 0; i < c.size(); ++i) {
      next[i + 1] += c[i];
      next[i] -= r * c[i];
    }
    c = next;
  }
  return c;
}

// How far round-off in the coefficients alone can move the simple root r: the first-order
// perturbation ε Σ|c_k||r|^k / |p'(r)|.
double root_condition(const std::vector<double>& c, double r) {
  double magnitude = 0, slope = 0;
  for (size_t k = 0; k < c.size(); ++k) {
    magnitude += std::abs(c[k]) * std::pow(std::abs(r), static_cast<double>(k));
    if (k > 0) slope += k * c[k] * std::pow(r, static_cast<double>(k - 1));
  }
  return 1.2e-16 * magnitude / std::abs(slope);
}

// Roots must match to within `tol` plus 20 times what the coefficients' round-off allows.
void expect_roots(const std::vector<double>& c, double a, double b, std::vector<double> expected,
                  double tol) {
  std::sort(expected.begin(), expected.end());
  const PolynomialRoots found = polynomial_roots(c, a, b);
  ASSERT_EQ(found.count, static_cast<int>(expected.size()));
  for (int i = 0; i < found.count; ++i) {
    const double allowed = tol + 20 * root_condition(c, expected[i]);
    EXPECT_NEAR(found.x[i], expected[i], allowed) << i;
    if (i > 0) {
      EXPECT_LT(found.x[i - 1], found.x[i]);
    }
  }
}

TEST(Polynomial, EvaluatesByHorner) {
  const std::vector<double> c{1, -2, 3};
  EXPECT_DOUBLE_EQ(evaluate_polynomial(c, 2.0), 1 - 4 + 12);
}

TEST(Polynomial, KnownRootsOfEachDegree) {
  expect_roots({-3, 2}, -10, 10, {1.5}, 1e-15);
  expect_roots(from_roots({-1, 2}), -10, 10, {-1, 2}, 1e-14);
  expect_roots(from_roots({-1, 0.5, 2}, -3), -10, 10, {-1, 0.5, 2}, 1e-13);
  expect_roots(from_roots({-2, -1, 1, 3}), -10, 10, {-2, -1, 1, 3}, 1e-12);
  expect_roots(from_roots({-2, -1, 0, 1, 3}, 0.5), -10, 10, {-2, -1, 0, 1, 3}, 1e-12);
  expect_roots(from_roots({1, 2, 3, 4, 5, 6}), 0, 10, {1, 2, 3, 4, 5, 6}, 1e-10);
}

TEST(Polynomial, OnlyRootsInsideTheInterval) {
  const auto c = from_roots({1, 2, 3, 4, 5, 6});
  expect_roots(c, 2.5, 4.5, {3, 4}, 1e-10);
  expect_roots(c, 6.5, 100, {}, 0);
  // Roots exactly at the ends count when p > 0 next to them inside the interval.
  expect_roots(from_roots({0, 1}), 0, 1, {}, 0);  // x² − x < 0 inside: {p > 0} is empty
  expect_roots(from_roots({0, 1}, -1), 0, 1, {0, 1}, 0);
  expect_roots(from_roots({0, 1}), -1, 0.5, {0}, 0);
}

TEST(Polynomial, ClusteredRoots) {
  expect_roots(from_roots({1, 1.001, 1.002, 1.003}), 0, 2, {1, 1.001, 1.002, 1.003}, 1e-12);
  expect_roots(from_roots({0.5, 0.51, 0.52, 0.53, 0.54, 0.55}), 0, 2,
               {0.5, 0.51, 0.52, 0.53, 0.54, 0.55}, 1e-12);
}

TEST(Polynomial, NearDoubleRootsStaySeparate) {
  for (double gap : {1e-4, 1e-6, 1e-7}) {
    const auto c = from_roots({1, 1 + gap, -2, 3});
    const PolynomialRoots r = polynomial_roots(c, 0, 2);
    ASSERT_EQ(r.count, 2) << gap;
    // The pair is ill-conditioned (error ~ ε / gap) but must stay apart and in order.
    EXPECT_NEAR(r.x[0], 1, 0.05 * gap);
    EXPECT_NEAR(r.x[1], 1 + gap, 0.05 * gap);
  }
}

TEST(Polynomial, TangentRootsFollowTheInsideConvention) {
  // (x − 1)² touches 0 from above: a boundary point of {p > 0}, reported once.
  const PolynomialRoots touch = polynomial_roots(from_roots({1, 1}), 0, 2);
  ASSERT_EQ(touch.count, 1);
  EXPECT_EQ(touch.x[0], 1.0);
  // −(x − 1)² touches from below: {p > 0} is empty, so no root.
  EXPECT_EQ(polynomial_roots(from_roots({1, 1}, -1), 0, 2).count, 0);
  // A triple root changes sign; its accuracy is ε^(1/3).
  const PolynomialRoots triple = polynomial_roots(from_roots({0.5, 0.5, 0.5}), 0, 2);
  ASSERT_EQ(triple.count, 1);
  EXPECT_NEAR(triple.x[0], 0.5, 1e-4);
}

TEST(Polynomial, VanishingLeadingCoefficientsLowerTheDegree) {
  expect_roots({-2, 1, 0, 0, 0, 0, 0}, -10, 10, {2}, 1e-15);
  expect_roots({1, 0, 0}, -10, 10, {}, 0);
  expect_roots({0, 0, 0}, -10, 10, {}, 0);
  // A tiny leading coefficient: a quadratic with a far-away third root.
  auto c = from_roots({-1, 1});
  c.push_back(1e-12);
  expect_roots(c, -5, 5, {-1, 1}, 1e-10);
}

TEST(Polynomial, FirstRootIsTheSmallest) {
  const auto c = from_roots({0.2, 0.7, 1.3}, -2);
  const auto first = first_polynomial_root(c, 0, 2);
  ASSERT_TRUE(first);
  EXPECT_NEAR(*first, 0.2, 1e-14);
  EXPECT_NEAR(*first_polynomial_root(c, 0.3, 2), 0.7, 1e-14);
  EXPECT_FALSE(first_polynomial_root(c, 1.4, 2));
}

TEST(Polynomial, RandomRootsAreAllFound) {
  Rng rng(7);
  for (int trial = 0; trial < 2000; ++trial) {
    const int degree = 1 + static_cast<int>(rng.uniform() * kMaxPolynomialDegree);
    std::vector<double> roots;
    while (static_cast<int>(roots.size()) < degree) {
      const double r = 2 * rng.uniform() - 1;
      bool separated = true;
      for (double s : roots) separated &= std::abs(r - s) > 1e-2;
      if (separated) roots.push_back(r);
    }
    const double scale = (rng.uniform() < 0.5 ? -1 : 1) * std::pow(10.0, 4 * rng.uniform() - 2);
    expect_roots(from_roots(roots, scale), -1.5, 1.5, roots, 1e-9);
  }
}

}  // namespace polynomial_test
}  // namespace nimbus
