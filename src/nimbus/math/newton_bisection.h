#pragma once
// Safeguarded Newton–bisection for a bracketed sign switch: Newton where it converges, bisection
// where it would leave the bracket or stalls, so it never fails and is quadratic near simple roots.

#include <cmath>
#include <limits>

namespace nimbus {

// `f(x)` returns {value, derivative} (any struct with members `value` and `slope`). Requires that
// the predicate f > 0 differs at lo and hi (`inside_lo` is its value at lo). Returns a point at
// which the predicate switches, within a few ulps.
template <class Fn>
double newton_bisection(const Fn& f, double lo, double hi, bool inside_lo) {
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  double x = 0.5 * (lo + hi);
  double last_step = hi - lo;
  for (int iteration = 0; iteration < 200; ++iteration) {
    const auto fx = f(x);
    if (fx.value == 0) return x;
    if ((fx.value > 0) == inside_lo)
      lo = x;
    else
      hi = x;
    double next = x - fx.value / fx.slope;
    const double step = std::abs(next - x);
    // Bisect when Newton leaves the bracket (or divides by 0) or converges no faster than
    // bisection.
    if (!(next > lo && next < hi) || step > 0.5 * last_step) {
      next = 0.5 * (lo + hi);
      if (next <= lo || next >= hi) return x;
    }
    last_step = std::abs(next - x);
    if (last_step <= 2 * kEps * std::abs(next)) return next;
    x = next;
  }
  return x;
}

}  // namespace nimbus
