#pragma once
// Real roots of polynomials of degree <= 6 on an interval, in double precision, after Yuksel,
// "High-Performance Polynomial Root Finding for Graphics" (HPG 2022): the roots of p' split
// [a, b] into intervals on which p is monotone (found the same way, recursively), and each one
// whose ends differ in sign holds exactly one root, found by safeguarded Newton–bisection.
//
// A "root" here is a boundary point of the set {x : p(x) > 0}: every root of odd multiplicity,
// plus an even-multiplicity root only where p evaluates to exactly 0 with p > 0 on both sides.
// A tangent touch from below is no root: along a ray it does not enter the solid.

#include <array>
#include <optional>
#include <span>

namespace nimbus {

constexpr int kMaxPolynomialDegree = 6;

struct PolynomialRoots {
  std::array<double, kMaxPolynomialDegree> x;
  int count = 0;
};

// p(x) = c[0] + c[1] x + ... + c[n] x^n by Horner's rule.
double evaluate_polynomial(std::span<const double> c, double x);

// All roots in [a, b], increasing. c.size() - 1 <= kMaxPolynomialDegree.
PolynomialRoots polynomial_roots(std::span<const double> c, double a, double b);

// The first root in [a, b] (the first x where the predicate p > 0 switches), cheaper than
// polynomial_roots because it stops there.
std::optional<double> first_polynomial_root(std::span<const double> c, double a, double b);

}  // namespace nimbus
