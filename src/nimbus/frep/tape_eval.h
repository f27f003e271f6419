#pragma once
// The one interpreter of a tape, generic over the value type: double (at a point), Interval
// (over a box), Dual and DualInterval (along a ray, at t or over an interval of t) and DualGrad
// (value and gradient). `leaf(i)` supplies quadric i in that type; the tape does the rest.

#include <algorithm>
#include <array>

#include "nimbus/frep/quadric.h"
#include "nimbus/frep/tape.h"
#include "nimbus/math/box.h"
#include "nimbus/math/dual.h"
#include "nimbus/math/interval.h"

namespace nimbus {

// min(max(x, 0)³, kMaxPositiveCube) (math/interval.h).
inline double positive_cube(double x) {
  const double p = x > 0 ? x : 0.0;
  return std::min(p * p * p, kMaxPositiveCube);
}
inline bool nonpositive(double x) {
  return x <= 0;
}

template <class T, class Leaf>
T run_tape(const Tape& tape, const Leaf& leaf) {
  using std::max;
  using std::min;
  // One quadric (a sphere, a box's slab is three): its value is the result, without the register
  // file, whose set-up cost more than the quadric on the walk's gradients (render/manifold.cpp).
  if (tape.code.size() == 1 && tape.code[0].op == Op::Quadric) return leaf(tape.code[0].quadric);
  std::array<T, kMaxRegisters> r;
  for (const Instr& in : tape.code) {
    switch (in.op) {
      case Op::Quadric:
        r[in.dst] = leaf(in.quadric);
        break;
      case Op::Max:
        r[in.dst] = max(r[in.dst], r[in.src]);
        break;
      case Op::Min:
        r[in.dst] = min(r[in.dst], r[in.src]);
        break;
      case Op::Neg:
        r[in.dst] = -r[in.dst];
        break;
      case Op::AddCubePos:
        // A perturbation that is nowhere positive adds exactly nothing (eq. 2); most are.
        if (!nonpositive(r[in.src])) r[in.dst] = r[in.dst] + in.weight * positive_cube(r[in.src]);
        break;
    }
  }
  return r[0];
}

// F(p) and ∇F(p) in one pass (tape.h's gradient() keeps only the gradient).
inline DualGrad value_gradient(const Tape& tape, const Vec3& p) {
  return run_tape<DualGrad>(tape, [&](std::uint32_t i) {
    const Quadric& q = tape.quadrics[i];
    return DualGrad{q.eval_finite(p), q.gradient_finite(p)};
  });
}

// Encloses a quadric over a finite box by its centred form around the centre c:
//   F(c + h) = F(c) + ∇F(c)·h + Σ_i A_ii h_i² + A12 h1 h2 + A13 h1 h3 + A23 h2 h3,
// whose overestimate shrinks quadratically with the box (a plain interval Horner form's only
// linearly), every term in interval arithmetic.
inline Interval quadric_range(const Quadric& q, const Box& box) {
  if (!box.finite()) return {-Box::kInf, Box::kInf};
  const auto& a = q.a;
  const Vec3 centre = box.center();
  Interval c[3], h[3];
  for (int i = 0; i < 3; ++i) {
    c[i] = Interval::point(centre[i]);
    h[i] = {next_down(box.lo[i] - centre[i]), next_up(box.hi[i] - centre[i])};
  }
  const Interval gx = 2 * a[0] * c[0] + a[3] * c[1] + a[4] * c[2] + Interval::point(a[6]);
  const Interval gy = 2 * a[1] * c[1] + a[3] * c[0] + a[5] * c[2] + Interval::point(a[7]);
  const Interval gz = 2 * a[2] * c[2] + a[4] * c[0] + a[5] * c[1] + Interval::point(a[8]);
  // F(c) in the nested form of Quadric::eval.
  const Interval fx = a[0] * c[0] + a[3] * c[1] + a[4] * c[2] + Interval::point(a[6]);
  const Interval fy = a[1] * c[1] + a[5] * c[2] + Interval::point(a[7]);
  const Interval fz = a[2] * c[2] + Interval::point(a[8]);
  const Interval f_centre = c[0] * fx + c[1] * fy + c[2] * fz + Interval::point(a[9]);
  return f_centre + gx * h[0] + gy * h[1] + gz * h[2] + a[0] * square(h[0]) + a[1] * square(h[1]) +
         a[2] * square(h[2]) + a[3] * (h[0] * h[1]) + a[4] * (h[0] * h[2]) + a[5] * (h[1] * h[2]);
}

// The exact range (up to outward rounding) of a t² + b t + c and of its slope over t ∈ T, from
// the Taylor form around m, the vertex clamped into T: with m at the vertex the linear term
// vanishes, and with m at an end the two terms have the signs of the monotone piece, so neither
// overestimates.
inline DualInterval quadratic_range(const RayQuadratic& q, Interval t) {
  const double vertex = q.a != 0 ? -q.b / (2 * q.a) : t.lo;
  const double m = std::clamp(vertex, t.lo, t.hi);
  const Interval mi = Interval::point(m), b = Interval::point(q.b);
  const Interval value_m = (q.a * mi + b) * mi + Interval::point(q.c);
  const Interval slope_m = 2 * q.a * mi + b;
  const Interval dt = {next_down(t.lo - m), next_up(t.hi - m)};
  return {value_m + slope_m * dt + q.a * square(dt), 2 * q.a * t + b};
}

}  // namespace nimbus
