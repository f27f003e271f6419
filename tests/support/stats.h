#pragma once
// Statistics helpers for Monte Carlo tests: running mean and standard error, and chi-square
// critical values.

#include <cmath>
#include <cstdint>

namespace nimbus::test {

// ∫_a^b f by composite Simpson with n (even) intervals.
template <class F>
double simpson(F&& f, double a, double b, int n) {
  const double h = (b - a) / n;
  double s = f(a) + f(b);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4 : 2) * f(a + i * h);
  return s * h / 3;
}

// Running mean and variance (Welford 1962).
struct MeanVar {
  uint64_t n = 0;
  double mean = 0, m2 = 0;

  void add(double x) {
    ++n;
    const double d = x - mean;
    mean += d / double(n);
    m2 += d * (x - mean);
  }
  double variance() const { return n > 1 ? m2 / double(n - 1) : 0; }
  // Standard error of the mean.
  double std_error() const { return std::sqrt(variance() / double(n)); }
};

// The upper-tail standard normal quantile z with P(Z > z) = p, by bisection on erfc.
inline double normal_upper_quantile(double p) {
  double lo = 0, hi = 40;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// The chi-square critical value with k degrees of freedom at upper-tail probability p
// (Wilson & Hilferty 1931: (χ²/k)^{1/3} is close to normal, mean 1 − 2/(9k), variance 2/(9k)).
inline double chi_square_critical(int k, double p) {
  const double v = 2.0 / (9.0 * k);
  const double c = 1 - v + normal_upper_quantile(p) * std::sqrt(v);
  return k * c * c * c;
}

}  // namespace nimbus::test
