#include "nimbus/math/polynomial.h"

#include "nimbus/math/newton_bisection.h"

namespace nimbus {
namespace {

struct ValueSlope {
  double value, slope;
};

ValueSlope evaluate_with_derivative(const double* c, int degree, double x) {
  double p = c[degree], dp = 0;
  for (int i = degree - 1; i >= 0; --i) {
    dp = dp * x + p;
    p = p * x + c[i];
  }
  return {p, dp};
}

double horner(const double* c, int degree, double x) {
  double p = c[degree];
  for (int i = degree - 1; i >= 0; --i) p = p * x + c[i];
  return p;
}

// The boundary points of {p > 0} in [a, b] (c[degree] != 0), increasing, into `out`; returns
// how many. With `first_only` it stops after the first.
int switch_points(const double* c, int degree, double a, double b, double* out, bool first_only) {
  if (degree <= 0) return 0;
  // Between consecutive switch points of p' (and the ends), p is monotone: at most one root,
  // and only if the ends' signs differ.
  double derivative[kMaxPolynomialDegree];
  for (int i = 0; i < degree; ++i) derivative[i] = (i + 1) * c[i + 1];
  double nodes[kMaxPolynomialDegree + 2];
  nodes[0] = a;
  const int last = switch_points(derivative, degree - 1, a, b, nodes + 1, false) + 1;
  nodes[last] = b;
  double values[kMaxPolynomialDegree + 2];
  for (int k = 0; k <= last; ++k) values[k] = horner(c, degree, nodes[k]);

  const auto p = [&](double x) { return evaluate_with_derivative(c, degree, x); };
  int count = 0;
  const auto emit = [&](double x) {
    if (count == 0 || x > out[count - 1]) out[count++] = x;
    return first_only;
  };
  for (int k = 0; k <= last; ++k) {
    // An exact zero at a node is a root if p > 0 on either side of it.
    if (values[k] == 0 && ((k > 0 && values[k - 1] > 0) || (k < last && values[k + 1] > 0)))
      if (emit(nodes[k])) return count;
    if (k < last && ((values[k] > 0 && values[k + 1] < 0) || (values[k] < 0 && values[k + 1] > 0)))
      if (emit(newton_bisection(p, nodes[k], nodes[k + 1], values[k] > 0))) return count;
  }
  return count;
}

int effective_degree(std::span<const double> c) {
  int degree = static_cast<int>(c.size()) - 1;
  while (degree > 0 && c[degree] == 0) --degree;
  return degree;
}

}  // namespace

double evaluate_polynomial(std::span<const double> c, double x) {
  return c.empty() ? 0.0 : horner(c.data(), static_cast<int>(c.size()) - 1, x);
}

PolynomialRoots polynomial_roots(std::span<const double> c, double a, double b) {
  PolynomialRoots roots;
  if (c.empty()) return roots;
  roots.count = switch_points(c.data(), effective_degree(c), a, b, roots.x.data(), false);
  return roots;
}

std::optional<double> first_polynomial_root(std::span<const double> c, double a, double b) {
  double x;
  if (c.empty() || switch_points(c.data(), effective_degree(c), a, b, &x, true) == 0)
    return std::nullopt;
  return x;
}

}  // namespace nimbus
