#include "nimbus/frep/intersect.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <utility>
#include <vector>

#include "nimbus/frep/tape_eval.h"
#include "nimbus/math/dual.h"
#include "nimbus/math/newton_bisection.h"
#include "nimbus/math/polynomial.h"

namespace nimbus {
namespace {

std::optional<double> first_hit_quadric(const Quadric& quadric, const Ray& ray, double lo,
                                        double hi) {
  double roots[2];
  const int count = sign_change_roots(restrict_to_ray(quadric, ray), roots);
  for (int i = 0; i < count; ++i)
    if (roots[i] >= lo && roots[i] <= hi) return roots[i];
  return std::nullopt;
}

// A perturbation's restriction to the ray and its weight; a plain aggregate so that the stack
// array of them is not zero-filled on every call.
struct Bump {
  double a, b, c, weight;
  double at(double t) const { return (a * t + b) * t + c; }
  double slope(double t) const { return 2 * a * t + b; }
};

// F(t) = q0(t) + Σ_i w_i max(q_i(t), 0)³ with its derivative, unexpanded: the polish's reference.
Dual flat_free_form_at(const RayQuadratic& base, std::span<const Bump> bumps, double t) {
  Dual f{base.at(t), base.derivative(t)};
  for (const Bump& bump : bumps) {
    const double q = bump.at(t);
    if (q > 0) f = f + bump.weight * positive_cube(Dual{q, bump.slope(t)});
  }
  return f;
}

// Adds w (p0 + p1 s + p2 s²)³ to the degree-6 coefficients c.
void add_weighted_cube(double p0, double p1, double p2, double w, double c[7]) {
  const double s0 = p0 * p0, s1 = 2 * p0 * p1, s2 = p1 * p1 + 2 * p0 * p2, s3 = 2 * p1 * p2,
               s4 = p2 * p2;  // (p0 + p1 s + p2 s²)²
  c[0] += w * (s0 * p0);
  c[1] += w * (s0 * p1 + s1 * p0);
  c[2] += w * (s0 * p2 + s1 * p1 + s2 * p0);
  c[3] += w * (s1 * p2 + s2 * p1 + s3 * p0);
  c[4] += w * (s2 * p2 + s3 * p1 + s4 * p0);
  c[5] += w * (s3 * p2 + s4 * p1);
  c[6] += w * (s4 * p2);
}

// Eq. 1–2 with quadric perturbations: between consecutive roots of the q_i the active set
// {i : q_i > 0} is fixed, so F is a polynomial of degree <= 6 there. Each piece is expanded
// around its own start (for precision), its first root isolated, then polished by Newton on the
// unexpanded F.
std::optional<double> first_hit_flat(const Tape& tape, const Ray& ray, double t_end) {
  const RayQuadratic base = restrict_to_ray(tape.quadrics[0], ray);
  Bump bumps[kMaxFlatPerturbations];
  double breaks[2 * kMaxFlatPerturbations + 2];
  int bump_count = 0, break_count = 0;
  breaks[break_count++] = 0;
  for (size_t i = 0; i < tape.weights.size(); ++i) {
    const RayQuadratic q = restrict_to_ray(tape.quadrics[i + 1], ray);
    double roots[2];
    const int root_count = sign_change_roots(q, roots);
    bool crosses = false;
    for (int r = 0; r < root_count; ++r)
      if (roots[r] > 0 && roots[r] < t_end) {
        breaks[break_count++] = roots[r];
        crosses = true;
      }
    // Without a root inside, q_i keeps its sign over the segment: keep it only if positive.
    if (crosses || q.at(0.5 * t_end) > 0) bumps[bump_count++] = {q.a, q.b, q.c, tape.weights[i]};
  }
  breaks[break_count++] = t_end;
  std::sort(breaks, breaks + break_count);
  const std::span<const Bump> active_bumps(bumps, bump_count);

  bool inside_before = false;
  for (int k = 0; k + 1 < break_count; ++k) {
    const double u0 = breaks[k], u1 = breaks[k + 1];
    if (!(u1 > u0)) continue;
    const double mid = 0.5 * (u0 + u1);
    // Most pieces are far from the surface: conservative ranges of F and dF/dt over the piece
    // reject them, or show F monotone there, for a fraction of the root isolation's cost.
    const Interval piece{u0, u1};
    DualInterval range = quadratic_range(base, piece);
    for (const Bump& bump : active_bumps)
      if (bump.at(mid) > 0)
        range =
            range + bump.weight * positive_cube(quadratic_range({bump.a, bump.b, bump.c}, piece));
    if (range.value.excludes_zero()) {
      const bool inside = range.value.lo > 0;
      if (k > 0 && inside != inside_before) return u0;
      inside_before = inside;
      continue;
    }
    const auto f = [&](double t) { return flat_free_form_at(base, active_bumps, t); };
    if (range.slope.excludes_zero()) {
      const bool inside0 = f(u0).value > 0, inside1 = f(u1).value > 0;
      if (k > 0 && inside0 != inside_before) return u0;
      if (inside0 != inside1) return newton_bisection(f, u0, u1, inside0);
      inside_before = inside1;
      continue;
    }
    double c[7] = {base.at(u0), base.derivative(u0), base.a, 0, 0, 0, 0};
    int degree = 2;
    for (const Bump& bump : active_bumps)
      if (bump.at(mid) > 0) {
        add_weighted_cube(bump.at(u0), bump.slope(u0), bump.a, bump.weight, c);
        degree = 6;
      }
    // F is continuous across breaks; a switch exactly at one shows up between the pieces.
    if (k > 0 && (c[0] > 0) != inside_before) return u0;
    const std::span<const double> poly(c, degree + 1);
    if (const auto s = first_polynomial_root(poly, 0, u1 - u0)) {
      double t = u0 + *s;
      Dual f = flat_free_form_at(base, active_bumps, t);
      for (int step = 0; step < 3 && f.value != 0; ++step) {
        const double next = t - f.value / f.slope;
        if (!(next >= u0 && next <= u1)) break;
        const Dual g = flat_free_form_at(base, active_bumps, next);
        if (!(std::abs(g.value) < std::abs(f.value))) break;
        t = next;
        f = g;
      }
      return t;
    }
    inside_before = evaluate_polynomial(poly, u1 - u0) > 0;
  }
  return std::nullopt;
}

// CSG of quadrics: max, min and negation preserve "F > 0" as a boolean function of the leaves'
// "q_i > 0", so F can change sign only where some leaf does, at one of the leaves' roots. Walk the
// roots in order, flipping that leaf's sign, and evaluate the boolean with ±1 for the leaves;
// the signs come from the root structure, not from evaluating q_i near its own root.
std::optional<double> first_hit_quadric_csg(const Tape& tape, const Ray& ray, double t_end) {
  struct Event {
    double t;
    std::uint32_t leaf;
  };
  thread_local std::vector<double> sign;
  thread_local std::vector<Event> events;
  sign.resize(tape.quadrics.size());
  events.clear();
  events.reserve(2 * tape.quadrics.size());
  for (std::uint32_t i = 0; i < sign.size(); ++i) {
    const RayQuadratic q = restrict_to_ray(tape.quadrics[i], ray);
    // The sign just after t = 0 (from the next nonzero derivative when q(0) is exactly 0).
    const bool positive = q.c > 0 || (q.c == 0 && (q.b > 0 || (q.b == 0 && q.a > 0)));
    sign[i] = positive ? 1.0 : -1.0;
    double roots[2];
    const int count = sign_change_roots(q, roots);
    for (int r = 0; r < count; ++r)
      if (roots[r] > 0 && roots[r] <= t_end) events.push_back({roots[r], i});
  }
  std::sort(events.begin(), events.end(), [](const Event& x, const Event& y) { return x.t < y.t; });
  const auto inside = [&] {
    return run_tape<double>(tape, [&](std::uint32_t i) { return sign[i]; }) > 0;
  };
  const bool inside_start = inside();
  for (size_t k = 0; k < events.size();) {
    const double t = events[k].t;
    for (; k < events.size() && events[k].t == t; ++k) sign[events[k].leaf] *= -1;
    if (inside() != inside_start) return t;
  }
  return std::nullopt;
}

// Anything else: subdivide [0, t_end] front to back. A piece whose range of F excludes 0 holds
// no crossing; one whose dF/dt excludes 0 is monotone, so it crosses iff its ends differ, and
// Newton–bisection finds it; a piece narrower than 1e-12 of the shape counts only by its ends.
std::optional<double> first_hit_general(const Tape& tape, const Ray& ray, double t_end) {
  struct Leaf {
    RayQuadratic q;
    // A perturbation <= 0 over the whole segment (most of them miss a given ray) adds exactly 0
    // on every piece, so its range over the whole segment serves for all of them, computed once.
    // Only there: elsewhere a range that does not shrink with the piece would stall subdivision.
    bool idle;
    DualInterval whole;
  };
  // Per-thread scratch, grown once: no allocation per ray.
  thread_local std::vector<Leaf> leaves;
  leaves.resize(tape.quadrics.size());
  for (size_t i = 0; i < leaves.size(); ++i) {
    Leaf& leaf = leaves[i];
    leaf.q = restrict_to_ray(tape.quadrics[i], ray);
    leaf.idle = false;
    if (tape.only_cubed[i]) {
      leaf.whole = quadratic_range(leaf.q, {0.0, t_end});
      leaf.idle = leaf.whole.value.hi <= 0;
    }
  }

  const auto value_at = [&](double t) {
    return run_tape<double>(tape, [&](std::uint32_t i) { return leaves[i].q.at(t); });
  };
  const auto dual_at = [&](double t) {
    return run_tape<Dual>(tape, [&](std::uint32_t i) {
      return Dual{leaves[i].q.at(t), leaves[i].q.derivative(t)};
    });
  };
  const auto range_over = [&](Interval t) {
    return run_tape<DualInterval>(tape, [&](std::uint32_t i) {
      const Leaf& leaf = leaves[i];
      return leaf.idle ? leaf.whole : quadratic_range(leaf.q, t);
    });
  };

  const double min_width = 1e-12 * tape.size / length(ray.d);
  constexpr int kStack = 160;
  // Where F vanishes identically along the ray (a ray in a boundary plane) no range ever
  // excludes 0; past this many pieces, every piece is decided by its ends alone.
  constexpr int kMaxPieces = 4096;
  Interval stack[kStack];
  int top = 0, pieces = 0;
  stack[top++] = {0.0, t_end};
  while (top > 0) {
    const Interval piece = stack[--top];
    const DualInterval f = range_over(piece);
    if (f.value.excludes_zero()) continue;
    const double mid = 0.5 * (piece.lo + piece.hi);
    const bool narrow = piece.hi - piece.lo <= min_width || !(mid > piece.lo && mid < piece.hi) ||
                        top + 2 > kStack || ++pieces > kMaxPieces;
    if (narrow || f.slope.excludes_zero()) {
      const bool inside_lo = value_at(piece.lo) > 0;
      if (inside_lo != (value_at(piece.hi) > 0))
        return newton_bisection(dual_at, piece.lo, piece.hi, inside_lo);
      continue;
    }
    stack[top++] = {mid, piece.hi};
    stack[top++] = {piece.lo, mid};
  }
  return std::nullopt;
}

}  // namespace

std::optional<double> first_hit(const Tape& tape, const Ray& ray, double t_min, double t_max) {
  if (!(t_min <= t_max) || tape.search_box.empty()) return std::nullopt;
  double t0 = t_min, t1 = t_max;
  const bool analytic = tape.kind == TapeKind::SingleQuadric;
  if ((!analytic || tape.bounds.bounded) && !clip_ray(tape.search_box, ray, t0, t1))
    return std::nullopt;
  // Re-parameterise around the entry point: coefficients and roots near 0 keep their precision.
  const double shift = std::isfinite(t0) ? t0 : 0.0;
  const Ray local{ray.at(shift), ray.d};
  const double lo = t0 - shift, hi = t1 - shift;
  std::optional<double> s;
  switch (tape.kind) {
    case TapeKind::SingleQuadric:
      s = first_hit_quadric(tape.quadrics[0], local, lo, hi);
      break;
    case TapeKind::FlatFreeForm:
      s = first_hit_flat(tape, local, hi);
      break;
    case TapeKind::QuadricCsg:
      s = first_hit_quadric_csg(tape, local, hi);
      break;
    case TapeKind::General:
      s = first_hit_general(tape, local, hi);
      break;
  }
  if (!s) return std::nullopt;
  return std::clamp(shift + *s, t_min, t_max);
}

}  // namespace nimbus
