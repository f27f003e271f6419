#include "nimbus/frep/bounds.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <queue>
#include <vector>

#include "nimbus/frep/tape.h"
#include "nimbus/math/symmetric_eigen.h"

namespace nimbus {

// The box of {F > 0} for one quadric F = xᵀQx + lᵀx + k. With N = −Q positive semidefinite
// and l in N's range, F = K − (x − c)ᵀ N (x − c) with c = N⁺l / 2 and K = k + lᵀc / 2: an
// ellipsoid, elliptic cylinder or slab, whose half-width along axis j is sqrt(K (N⁺)_jj) unless
// N's null space has a component along j. Anything else (hyperboloids, cones, paraboloids,
// half-spaces) is unbounded.
Box quadric_box(const Quadric& q) {
  const auto& a = q.a;
  const std::array<std::array<double, 3>, 3> n{{{-a[0], -a[3] / 2, -a[4] / 2},
                                                {-a[3] / 2, -a[1], -a[5] / 2},
                                                {-a[4] / 2, -a[5] / 2, -a[2]}}};
  const Vec3 l{a[6], a[7], a[8]};
  const double k = a[9];
  const SymmetricEigen eigen = symmetric_eigen(n);
  double largest = 0;
  for (double lambda : eigen.values) largest = std::max(largest, std::abs(lambda));
  // Eigenvalues and null-space components this small relative to the rest are round-off, e.g.
  // of a rotated cylinder.
  const double lambda_tol = 1e-10 * largest;
  const double l_tol = 1e-9 * (length(l) + std::sqrt(largest * std::abs(k)));
  constexpr double kAxisTol = 1e-9;

  bool range[3];
  for (int i = 0; i < 3; ++i) {
    if (eigen.values[i] < -lambda_tol) return Box::everything();  // indefinite
    range[i] = eigen.values[i] > lambda_tol;
    if (!range[i] && std::abs(dot(eigen.vectors[i], l)) > l_tol) return Box::everything();
  }
  Vec3 centre{};
  std::array<double, 3> n_pinv_diag{};
  for (int i = 0; i < 3; ++i) {
    if (!range[i]) continue;
    const Vec3& v = eigen.vectors[i];
    centre += v * (dot(v, l) / (2 * eigen.values[i]));
    for (int j = 0; j < 3; ++j) n_pinv_diag[j] += v[j] * v[j] / eigen.values[i];
  }
  const double peak = k + dot(l, centre) / 2;
  if (peak <= 0) return Box{};
  Box box;
  for (int j = 0; j < 3; ++j) {
    bool along_null = false;
    for (int i = 0; i < 3; ++i)
      if (!range[i] && std::abs(eigen.vectors[i][j]) > kAxisTol) along_null = true;
    // A relative 1e-12 covers the round-off of the formula itself.
    const double half = along_null ? Box::kInf : std::sqrt(peak * n_pinv_diag[j]) * (1 + 1e-12);
    box.lo[j] = centre[j] - half;
    box.hi[j] = centre[j] + half;
  }
  return box;
}

namespace {

Quadric operator+(const Quadric& p, const Quadric& q) {
  Quadric sum;
  for (int i = 0; i < 10; ++i) sum.a[i] = p.a[i] + q.a[i];
  return sum;
}

// What is known about one register's {F > 0}: a box around it and, where one is known, a quadric
// Q with {F > 0} ⊂ {Q > 0}.
struct Enclosure {
  Box box;
  std::optional<Quadric> quadric;
};

// Runs the tape on enclosures instead of values. An intersection of quadric sets lies inside
// {Q_a + Q_b > 0} (both positive ⇒ the sum is), which is what bounds a tilted cylinder cut by a
// slab, or a rotated box, whose every factor alone is unbounded along all axes.
Box combined_box(const Tape& tape) {
  std::array<Enclosure, kMaxRegisters> r;
  for (const Instr& in : tape.code) {
    Enclosure& dst = r[in.dst];
    const Enclosure& src = r[in.src];
    switch (in.op) {
      case Op::Quadric: {
        const Quadric& q = tape.quadrics[in.quadric];
        dst = {quadric_box(q), q};
        break;
      }
      case Op::Max:
        dst = {unite(dst.box, src.box), std::nullopt};
        break;
      case Op::Min:
        if (dst.quadric && src.quadric) {
          dst.quadric = *dst.quadric + *src.quadric;
          dst.box = intersect(dst.box, quadric_box(*dst.quadric));
        } else if (src.quadric) {
          dst.quadric = src.quadric;
        }
        dst.box = intersect(dst.box, src.box);
        break;
      // The complement of a bounded set is unbounded; a difference keeps its first operand's box.
      case Op::Neg:
        dst = {Box::everything(), std::nullopt};
        break;
      // F + w R_i <= F where w < 0; with w > 0 it is positive only where F or R_i is.
      case Op::AddCubePos:
        if (in.weight > 0) dst = {unite(dst.box, src.box), std::nullopt};
        break;
    }
  }
  return r[0].box;
}

constexpr int kMaxSplits = 21;          // binary splits, i.e. 7 octree levels
constexpr int kMaxEvaluations = 20000;  // per face, a cap for pathological shapes

struct Cell {
  Box box;
  int depth;
  double key;  // how far the cell reaches in the searched direction
};

// The farthest coordinate along ±axis of any point with F > 0 in `initial`, up to the size of
// the finest cells, searching cells best first: when a cell is accepted, every cell reaching
// farther has been shown empty. Empty optional when the whole box is.
std::optional<double> farthest(const Tape& tape, const Box& initial, int axis, bool upper) {
  const auto reach = [&](const Box& b) { return upper ? b.hi[axis] : -b.lo[axis]; };
  const auto later = [](const Cell& x, const Cell& y) {
    return x.key < y.key || (x.key == y.key && x.depth < y.depth);
  };
  std::priority_queue<Cell, std::vector<Cell>, decltype(later)> queue(later);
  queue.push({initial, 0, reach(initial)});
  for (int evaluations = 0; !queue.empty(); ++evaluations) {
    const Cell cell = queue.top();
    queue.pop();
    const Interval f = evaluate(tape, cell.box);
    if (f.hi <= 0) continue;
    if (f.lo > 0 || cell.depth == kMaxSplits || evaluations >= kMaxEvaluations)
      return upper ? cell.box.hi[axis] : cell.box.lo[axis];
    const Vec3 e = cell.box.extent();
    const int split = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    const double mid = 0.5 * (cell.box.lo[split] + cell.box.hi[split]);
    Box low = cell.box, high = cell.box;
    low.hi[split] = mid;
    high.lo[split] = mid;
    queue.push({low, cell.depth + 1, reach(low)});
    queue.push({high, cell.depth + 1, reach(high)});
  }
  return std::nullopt;
}

}  // namespace

Bounds compute_bounds(const Tape& tape) {
  const Box initial = combined_box(tape);
  if (initial.empty()) return {Box{}, true};
  if (!initial.finite()) return {initial, false};
  // A single quadric's box is already exact.
  if (tape.kind == TapeKind::SingleQuadric) return {initial, true};
  Box tight;
  for (int axis = 0; axis < 3; ++axis) {
    const auto lo = farthest(tape, initial, axis, false);
    const auto hi = farthest(tape, initial, axis, true);
    if (!lo || !hi) return {Box{}, true};
    tight.lo[axis] = *lo;
    tight.hi[axis] = *hi;
  }
  return {tight, true};
}

Bounds placed_bounds(const Tape& tape, const Bounds& local, const Mat4& placement) {
  if (!local.bounded || local.box.empty()) return local;
  Box placed;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 p{corner & 1 ? local.box.hi.x : local.box.lo.x,
                 corner & 2 ? local.box.hi.y : local.box.lo.y,
                 corner & 4 ? local.box.hi.z : local.box.lo.z};
    placed = unite(placed, Box{transform_point(placement, p), transform_point(placement, p)});
  }
  // A relative 1e-12 covers the transform's round-off (a few ulps of the largest coordinate).
  const double reach =
      std::max({std::abs(placed.lo.x), std::abs(placed.lo.y), std::abs(placed.lo.z),
                std::abs(placed.hi.x), std::abs(placed.hi.y), std::abs(placed.hi.z)});
  const double pad = 1e-12 * (reach + length(placed.extent())) + 1e-300;
  placed = {placed.lo - Vec3{pad, pad, pad}, placed.hi + Vec3{pad, pad, pad}};
  return {intersect(placed, combined_box(tape)), true};
}

}  // namespace nimbus
