#pragma once
// Closed intervals [lo, hi] with outward rounding: every computed bound is moved one ulp away
// from the interval (std::nextafter towards ∓∞), so the exact real range of an expression over
// its interval arguments always lies inside the computed one. Infinite bounds are allowed;
// products of 0 and ∞ are the caller's to avoid.

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>

namespace nimbus {

// std::nextafter(x, -∞) and std::nextafter(x, +∞), inline: they sit on the ray-casting hot path.
inline double next_down(double x) {
  if (x != x || x == -std::numeric_limits<double>::infinity()) return x;
  if (x == 0) return -std::numeric_limits<double>::denorm_min();
  const auto bits = std::bit_cast<std::uint64_t>(x);
  return std::bit_cast<double>(x > 0 ? bits - 1 : bits + 1);
}
inline double next_up(double x) {
  return -next_down(-x);
}

struct Interval {
  double lo, hi;

  static constexpr Interval point(double x) { return {x, x}; }
  constexpr bool contains(double x) const { return lo <= x && x <= hi; }
  // True when every value is > 0 or every value is < 0: the range cannot hold a root.
  constexpr bool excludes_zero() const { return lo > 0 || hi < 0; }
};

inline Interval operator+(Interval a, Interval b) {
  return {next_down(a.lo + b.lo), next_up(a.hi + b.hi)};
}
inline Interval operator-(Interval a) {
  return {-a.hi, -a.lo};
}
inline Interval operator-(Interval a, Interval b) {
  return {next_down(a.lo - b.hi), next_up(a.hi - b.lo)};
}
inline Interval operator*(Interval a, Interval b) {
  const double p0 = a.lo * b.lo, p1 = a.lo * b.hi, p2 = a.hi * b.lo, p3 = a.hi * b.hi;
  return {next_down(std::min(std::min(p0, p1), std::min(p2, p3))),
          next_up(std::max(std::max(p0, p1), std::max(p2, p3)))};
}
inline Interval operator*(double s, Interval a) {
  return s >= 0 ? Interval{next_down(s * a.lo), next_up(s * a.hi)}
                : Interval{next_down(s * a.hi), next_up(s * a.lo)};
}

inline Interval square(Interval a) {
  if (a.lo >= 0) return {next_down(a.lo * a.lo), next_up(a.hi * a.hi)};
  if (a.hi <= 0) return {next_down(a.hi * a.hi), next_up(a.lo * a.lo)};
  return {0.0, next_up(std::max(a.lo * a.lo, a.hi * a.hi))};
}

// x³ rounded down / up. Two products means two roundings, so each one is bounded on its own.
inline double cube_up(double x);
inline double cube_down(double x) {
  return x >= 0 ? next_down(next_down(x * x) * x) : -cube_up(-x);
}
inline double cube_up(double x) {
  return x >= 0 ? next_up(next_up(x * x) * x) : -cube_down(-x);
}

// x³ is increasing, so its range is the cubes of the ends.
inline Interval cube(Interval a) {
  return {cube_down(a.lo), cube_up(a.hi)};
}

// The most a perturbation's max(F, 0)³ counts (eq. 2), in every evaluation of it (point,
// interval, dual, gradient): past it the cube saturates. A perturbation of radius 1e100 has F up
// to 1e200, whose cube overflows, and two such terms of weights ±1e15 made F NaN (issue 44).
// Saturated, a term is at most 1e15 · 1e280 and the sum of 20 000 of them (kMaxTapeQuadrics)
// stays finite; no scene short of F ≈ 4.6e93 is changed.
inline constexpr double kMaxPositiveCube = 1e280;

// x clamped to ±kMaxPositiveCube, and NaN (0 · ∞ in a derivative) to 0.
inline double saturate_cube_term(double x) {
  return x >= kMaxPositiveCube    ? kMaxPositiveCube
         : x <= -kMaxPositiveCube ? -kMaxPositiveCube
         : x == x                 ? x
                                  : 0.0;
}

// min(max(x, 0)³, kMaxPositiveCube), the perturbation R of eq. 2. An exact 0 stays exactly 0.
inline Interval positive_cube(Interval a) {
  return {a.lo > 0 ? std::min(cube_down(a.lo), kMaxPositiveCube) : 0.0,
          a.hi > 0 ? std::min(cube_up(a.hi), kMaxPositiveCube) : 0.0};
}

// True when max(x, 0)³ is exactly 0 over the whole interval.
inline bool nonpositive(Interval a) {
  return a.hi <= 0;
}

inline Interval max(Interval a, Interval b) {
  return {std::max(a.lo, b.lo), std::max(a.hi, b.hi)};
}
inline Interval min(Interval a, Interval b) {
  return {std::min(a.lo, b.lo), std::min(a.hi, b.hi)};
}
inline Interval hull(Interval a, Interval b) {
  return {std::min(a.lo, b.lo), std::max(a.hi, b.hi)};
}

}  // namespace nimbus
