#pragma once
// Forward-mode derivatives for the operations an FRep tape uses (+, scalar ×, −, max, min and
// max(x, 0)³): a value with its derivative along a ray (Dual), the same over an interval of t
// (DualInterval, for monotonicity tests), and a value with its spatial gradient (DualGrad).

#include "nimbus/math/interval.h"
#include "nimbus/math/vec3.h"

namespace nimbus {

struct Dual {
  double value, slope;  // f(t) and df/dt
};

struct DualInterval {
  Interval value, slope;  // ranges of f and df/dt over an interval of t
};

struct DualGrad {
  double value;
  Vec3 grad;
};

inline Dual operator+(Dual a, Dual b) {
  return {a.value + b.value, a.slope + b.slope};
}
inline Dual operator*(double s, Dual a) {
  return {s * a.value, s * a.slope};
}
inline Dual operator-(Dual a) {
  return {-a.value, -a.slope};
}
// Where the arguments tie, either one-sided derivative is a valid choice.
inline Dual max(Dual a, Dual b) {
  return a.value >= b.value ? a : b;
}
inline Dual min(Dual a, Dual b) {
  return a.value <= b.value ? a : b;
}
// d/dt max(f, 0)³ = 3 max(f, 0)² f', saturated at kMaxPositiveCube (interval.h), where the
// slope is 0.
inline Dual positive_cube(Dual a) {
  const double p = a.value > 0 ? a.value : 0.0;
  const double cube = p * p * p;
  if (cube > kMaxPositiveCube) return {kMaxPositiveCube, 0.0};
  return {cube, saturate_cube_term(3 * p * p * a.slope)};
}

// True when max(f, 0)³ and its derivative are exactly 0.
inline bool nonpositive(Dual a) {
  return a.value <= 0;
}
inline bool nonpositive(DualInterval a) {
  return a.value.hi <= 0;
}
inline bool nonpositive(const DualGrad& a) {
  return a.value <= 0;
}

inline DualInterval operator+(DualInterval a, DualInterval b) {
  return {a.value + b.value, a.slope + b.slope};
}
inline DualInterval operator*(double s, DualInterval a) {
  return {s * a.value, s * a.slope};
}
inline DualInterval operator-(DualInterval a) {
  return {-a.value, -a.slope};
}
// Where one argument dominates over the whole interval, max is that argument; elsewhere its
// slope is one of the two slopes (a strictly monotone max of strictly monotone pieces), hence
// the hull.
inline DualInterval max(DualInterval a, DualInterval b) {
  if (a.value.lo >= b.value.hi) return a;
  if (b.value.lo >= a.value.hi) return b;
  return {max(a.value, b.value), hull(a.slope, b.slope)};
}
inline DualInterval min(DualInterval a, DualInterval b) {
  if (a.value.hi <= b.value.lo) return a;
  if (b.value.hi <= a.value.lo) return b;
  return {min(a.value, b.value), hull(a.slope, b.slope)};
}
inline DualInterval positive_cube(DualInterval a) {
  // Where the cube saturates its slope is 0: p is cut to the cube root of the limit, and where
  // only part of the interval saturates the slope's range takes in 0.
  constexpr double kRoot = 2.2e93;  // above cbrt(kMaxPositiveCube) = 2.154e93
  Interval p = max(a.value, Interval::point(0.0));
  if (p.lo > kRoot) return {positive_cube(a.value), Interval::point(0.0)};
  if (p.hi > kRoot) p = {0.0, kRoot};
  const Interval slope = 3.0 * (square(p) * a.slope);
  if (slope.lo != slope.lo || slope.hi != slope.hi)
    return {positive_cube(a.value),
            {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()}};
  return {positive_cube(a.value), slope};
}

inline DualGrad operator+(const DualGrad& a, const DualGrad& b) {
  return {a.value + b.value, a.grad + b.grad};
}
inline DualGrad operator*(double s, const DualGrad& a) {
  return {s * a.value, s * a.grad};
}
inline DualGrad operator-(const DualGrad& a) {
  return {-a.value, -a.grad};
}
inline DualGrad max(const DualGrad& a, const DualGrad& b) {
  return a.value >= b.value ? a : b;
}
inline DualGrad min(const DualGrad& a, const DualGrad& b) {
  return a.value <= b.value ? a : b;
}
inline DualGrad positive_cube(const DualGrad& a) {
  const double p = a.value > 0 ? a.value : 0.0;
  const double cube = p * p * p;
  if (cube > kMaxPositiveCube) return {kMaxPositiveCube, Vec3{}};
  const Vec3 g = (3 * p * p) * a.grad;
  return {cube, {saturate_cube_term(g.x), saturate_cube_term(g.y), saturate_cube_term(g.z)}};
}

}  // namespace nimbus
