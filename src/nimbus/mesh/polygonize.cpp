#include "nimbus/mesh/polygonize.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <optional>
#include <unordered_map>
#include <vector>

#include "nimbus/frep/intersect.h"
#include "nimbus/math/symmetric_eigen.h"

namespace nimbus {

namespace {

// Grid corners sit off the round coordinates shapes are usually placed at: a shift of this many
// cells, (3 − √5) / 2.
constexpr double kGridShift = 0.3819660112501051;
// A grid whose failing faces are at most one in this many has them bisected (bisect_failing_faces)
// rather than the whole grid refined. Bisecting a quarter of a grid's faces adds fewer faces than
// the refined grid would have, and takes less time: the free form of four perturbations at
// ε = 0.004 fails at 7 % of its first grid's faces, bisected to 2 052 faces where the refined grid
// had 3 860; a ring at 0.002, 7 556 where refining gave 35 904 (docs/meshes.md).
constexpr std::size_t kFewFailing = 4;
// A face's sample point where F changes sign within this fraction of the error bound along the
// face's normal is that near the surface: two or three values of F show it, where measuring it
// takes two exact root searches. Such a point fails nothing, and the largest distance, which the
// report and the next grid need, is measured exactly wherever it is below this (exact_largest).
constexpr double kSignProbe = 0.5;
// A refined grid aims its cell at this fraction of the error bound (the faces' error falling as
// the square of the cell), leaving room for the prediction's miss.
constexpr double kAimedError = 0.7;
// At most this many cells along an axis (a cell's key packs 21 bits per axis).
constexpr int kMaxAxisCells = (1 << 21) - 2;
// A cell whose corners share a sign is searched for a hidden piece of the shape down to boxes
// this many times smaller (or the error bound, if larger).
constexpr double kHiddenSearch = 8;
// Normals more than 30° apart at a mesh edge's ends may be those of two faces of a sharp edge
// between them (split_folds).
constexpr double kFoldCos = 0.8660254037844387;
// A point where sharp edges meet is taken where F changes sign within this fraction of the error
// bound of it: exact to round-off where the faces are planes.
constexpr double kFoldTolerance = 0.01;
// Cells per task when the pruning recursion runs in parallel.
constexpr std::int64_t kParallelCells = 4096;

using Cell = std::array<int, 3>;

struct Grid {
  Vec3 origin;
  double h = 0;
  Cell n{};  // cells per axis
  Vec3 point(double i, double j, double k) const {
    return {origin.x + i * h, origin.y + j * h, origin.z + k * h};
  }
  Vec3 corner(const Cell& c) const { return point(c[0], c[1], c[2]); }
};

std::uint64_t key(const Cell& c) {
  return (std::uint64_t(c[0]) << 42) | (std::uint64_t(c[1]) << 21) | std::uint64_t(c[2]);
}

// Whether interval arithmetic proves the box all inside (F > 0) or free of inside points
// (F <= 0: culled quadrics are enclosed by [-inf, 0], whose upper end touches 0).
bool one_sided(const Tape& tape, const Box& box) {
  const Interval f = evaluate(tape, box);
  return f.lo > 0 || f.hi <= 0;
}

// The cells of [lo, hi) whose box interval arithmetic cannot prove one-sided, in the
// recursion's order (children by octant).
std::vector<Cell> collect(const Tape& tape, const Grid& g, const Cell& lo, const Cell& hi) {
  if (one_sided(tape, Box{g.corner(lo), g.corner(hi)})) return {};
  if (hi[0] - lo[0] == 1 && hi[1] - lo[1] == 1 && hi[2] - lo[2] == 1) return {lo};
  std::array<std::pair<Cell, Cell>, 8> parts;
  int count = 0;
  for (int o = 0; o < 8; ++o) {
    Cell a = lo, b = hi;
    bool empty = false;
    for (int k = 0; k < 3; ++k) {
      const int mid = lo[size_t(k)] + (hi[size_t(k)] - lo[size_t(k)] + 1) / 2;
      if (o >> k & 1) {
        a[size_t(k)] = mid;
        empty |= mid >= hi[size_t(k)];
      } else {
        b[size_t(k)] = mid;
      }
    }
    if (!empty) parts[size_t(count++)] = {a, b};
  }
  std::array<std::vector<Cell>, 8> found;
  const std::int64_t volume =
      std::int64_t(hi[0] - lo[0]) * std::int64_t(hi[1] - lo[1]) * std::int64_t(hi[2] - lo[2]);
  auto visit = [&](int i) {
    found[size_t(i)] = collect(tape, g, parts[size_t(i)].first, parts[size_t(i)].second);
  };
  if (volume > kParallelCells)
    tbb::parallel_for(0, count, visit);
  else
    for (int i = 0; i < count; ++i) visit(i);
  std::vector<Cell> out;
  for (int i = 0; i < count; ++i)
    out.insert(out.end(), found[size_t(i)].begin(), found[size_t(i)].end());
  return out;
}

// Corner o of a cell (bit k: +1 along axis k).
Cell corner_of(const Cell& c, int o) {
  return {c[0] + (o & 1), c[1] + (o >> 1 & 1), c[2] + (o >> 2 & 1)};
}

// Cube edge e = 4 axis + (b1 + 2 b2): along `axis` from the corner whose bits on the other two
// axes, (axis + 1) % 3 and (axis + 2) % 3, are b1 and b2.
int edge_corner(int e, int end) {
  const int axis = e / 4, b1 = e & 1, b2 = e >> 1 & 1;
  return end << axis | b1 << ((axis + 1) % 3) | b2 << ((axis + 2) % 3);
}
int edge_of(int axis, int b1, int b2) {
  return 4 * axis + b1 + 2 * b2;
}

// A root of F on a grid edge from a (lower) to b, and the outward normal there.
struct EdgePoint {
  Vec3 p, n;
};

Vec3 outward(const Tape& tape, const Vec3& p) {
  const Vec3 g = gradient(tape, p);
  const double len = length(g);
  return len > 0 ? g * (-1 / len) : Vec3{0, 0, 0};
}

// The root of F nearest p on the line through p in direction d (unit), signed along d, within
// `reach`; none if there is none.
std::optional<double> nearest_root(const Tape& tape, const Vec3& p, const Vec3& d, double reach) {
  // Each search starts a hair behind p, so that a root at p itself (a point on the surface, where
  // F is 0 to round-off) is a sign change inside the interval.
  const double hair = 1e-6 * reach;
  std::optional<double> best;
  if (const auto t = first_hit(tape, Ray{p - d * hair, d}, 0, reach + hair)) best = *t - hair;
  const double behind = best ? std::abs(*best) : reach;
  if (const auto t = first_hit(tape, Ray{p + d * hair, -d}, 0, behind + hair))
    if (!best || *t - hair < std::abs(*best)) best = -(*t - hair);
  return best;
}

EdgePoint edge_point(const Tape& tape, const Vec3& a, const Vec3& b, double fa) {
  double t;
  if (const auto hit = first_hit(tape, Ray{a, b - a}, 0, 1)) {
    t = *hit;
  } else {  // round-off kept the exact search from seeing the change: bisection
    double lo = 0, hi = 1;
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      ((evaluate(tape, a + (b - a) * mid) > 0) == (fa > 0) ? lo : hi) = mid;
    }
    t = 0.5 * (lo + hi);
  }
  const Vec3 p = a + (b - a) * t;
  return {p, outward(tape, p)};
}

// The point minimising Σ (n_i · (x − p_i))², nearest the mass point along the directions the
// planes leave free (eigenvalues below a tenth of the largest are dropped): on a sharp edge or
// corner where the planes meet, on the mean plane elsewhere. The mass point where the solution
// leaves the cell.
Vec3 qef_vertex(const std::vector<EdgePoint>& points, const Box& cell, Vec3& mass) {
  mass = Vec3{0, 0, 0};
  for (const EdgePoint& e : points) mass += e.p;
  mass = mass / double(points.size());
  std::array<std::array<double, 3>, 3> ata{};
  Vec3 r{0, 0, 0};  // Aᵀ (b − A mass)
  for (const EdgePoint& e : points) {
    const double d = dot(e.n, e.p - mass);
    for (int i = 0; i < 3; ++i) {
      r[i] += e.n[i] * d;
      for (int j = 0; j < 3; ++j) ata[size_t(i)][size_t(j)] += e.n[i] * e.n[j];
    }
  }
  const SymmetricEigen eig = symmetric_eigen(ata);
  const double largest = std::max({eig.values[0], eig.values[1], eig.values[2]});
  Vec3 x = mass;
  for (int k = 0; k < 3; ++k)
    if (eig.values[size_t(k)] > 0.1 * largest && largest > 0)
      x += eig.vectors[size_t(k)] * (dot(eig.vectors[size_t(k)], r) / eig.values[size_t(k)]);
  return cell.contains(x) ? x : mass;
}

struct CellVertices {
  std::array<std::int8_t, 12> vertex_of_edge;  // a loop's index in the cell, or -1
  int loops = 0;
  std::uint32_t first = 0;  // global index of loop 0
};

int find(std::array<int, 12>& parent, int i) {
  while (parent[size_t(i)] != i) i = parent[size_t(i)];
  return i;
}

// The faces of a cube: axis, side, and the four corners in cyclic order.
struct Face {
  int axis, side;
  std::array<int, 4> corners;
};
std::array<Face, 6> cube_faces() {
  std::array<Face, 6> faces{};
  int f = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3, s = side << axis;
      faces[size_t(f++)] = {axis, side, {s, s | 1 << a1, s | 1 << a1 | 1 << a2, s | 1 << a2}};
    }
  return faces;
}

// The cube edge joining two corners that differ in one bit.
int edge_between(int c0, int c1) {
  const int diff = c0 ^ c1, axis = diff == 1 ? 0 : diff == 2 ? 1 : 2;
  const int low = c0 & c1, a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  return edge_of(axis, low >> a1 & 1, low >> a2 & 1);
}

// One grid: the mesh, and whether a cell hides part of the shape between its corners (a piece
// thinner than the cell that no corner sees).
struct GridMesh {
  TriangleMesh mesh;
  std::uint64_t cells = 0;
  double vertex_error = 0;
  bool hidden = false;
};

// Whether the box, whose corners are all inside (or all outside), holds a point of the other
// sign more than `depth` from the surface: a piece of the shape (or a hole) that the grid does
// not see and whose loss would cost more than the error bound. Point values at the centres of
// the boxes interval arithmetic cannot clear, down to boxes of size `finest`. A shallow cap of
// the surface across a face is no such piece: its points lie within the cap's depth.
bool hides_other_sign(const Tape& tape, const Box& box, bool inside, double depth, double finest) {
  if (one_sided(tape, box)) return false;
  const Vec3 x = box.center();
  const Vec3 e = box.extent();
  const double size = std::max({e.x, e.y, e.z});
  if ((evaluate(tape, x) > 0) != inside) {
    const Vec3 n = outward(tape, x);
    if (length(n) > 0 && distance_along(tape, x, n, 2 * size) > depth) return true;
  }
  if (size <= finest) return false;
  for (int o = 0; o < 8; ++o) {
    Box child;
    for (int k = 0; k < 3; ++k) {
      const double mid = 0.5 * (box.lo[k] + box.hi[k]);
      child.lo[k] = o >> k & 1 ? mid : box.lo[k];
      child.hi[k] = o >> k & 1 ? box.hi[k] : mid;
    }
    if (hides_other_sign(tape, child, inside, depth, finest)) return true;
  }
  return false;
}

// Whether a face (a, b, c) has three points in a line (three cells' vertices on one sharp edge),
// and so no normal, or is turned against the surface's normal (two vertices on a sharp edge in
// the other order along it than their cells): `outward`, or the gradient's at its centroid.
bool misshapen(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& outward) {
  const Vec3 u = b - a, w = c - a, n = cross(u, w);
  if (length(n) <= 1e-6 * std::max(dot(u, u), dot(w, w))) return true;
  return dot(n, outward) < 0;
}
bool misshapen(const Tape& tape, const Vec3& a, const Vec3& b, const Vec3& c) {
  return misshapen(a, b, c, outward(tape, (a + b + c) / 3.0));
}

GridMesh mesh_grid(const Tape& tape, const Grid& g, double error) {
  GridMesh out;
  std::vector<Cell> cells = collect(tape, g, {0, 0, 0}, g.n);
  std::sort(cells.begin(), cells.end(),
            [](const Cell& a, const Cell& b) { return key(a) < key(b); });
  out.cells = cells.size();
  const std::array<Face, 6> faces = cube_faces();
  std::vector<CellVertices> loops(cells.size());
  std::vector<std::array<double, 8>> values(cells.size());
  std::vector<char> hidden(cells.size(), 0);
  // Loops: the sign changes on each face pair into segments (an ambiguous face by the sign at
  // its centre), and segments join into the loops the surface makes on the cell's boundary.
  tbb::parallel_for(std::size_t{0}, cells.size(), [&](std::size_t i) {
    const Cell& c = cells[i];
    std::array<double, 8>& f = values[i];
    int inside = 0;
    for (int o = 0; o < 8; ++o) {
      f[size_t(o)] = evaluate(tape, g.corner(corner_of(c, o)));
      inside += f[size_t(o)] > 0;
    }
    CellVertices& v = loops[i];
    v.vertex_of_edge.fill(-1);
    if (inside == 0 || inside == 8) {
      hidden[i] = hides_other_sign(tape, Box{g.corner(c), g.corner(corner_of(c, 7))}, inside == 8,
                                   error, std::max(error, g.h / kHiddenSearch));
      return;
    }
    std::array<int, 12> parent;
    std::iota(parent.begin(), parent.end(), 0);
    auto join = [&](int a, int b) { parent[size_t(find(parent, a))] = find(parent, b); };
    for (const Face& face : faces) {
      std::array<int, 4> edge{};
      std::array<bool, 4> changes{};
      int count = 0;
      for (int k = 0; k < 4; ++k) {
        const int c0 = face.corners[size_t(k)], c1 = face.corners[size_t((k + 1) % 4)];
        edge[size_t(k)] = edge_between(c0, c1);
        changes[size_t(k)] = (f[size_t(c0)] > 0) != (f[size_t(c1)] > 0);
        count += changes[size_t(k)];
      }
      if (count == 2) {
        int first = -1;
        for (int k = 0; k < 4; ++k)
          if (changes[size_t(k)]) {
            if (first < 0)
              first = edge[size_t(k)];
            else
              join(first, edge[size_t(k)]);
          }
      } else if (count == 4) {
        // Corners 0 and 2 share a sign. If the centre has it too they connect across the face,
        // and the segments cut off corners 1 and 3; else corners 0 and 2.
        const Cell lo = corner_of(c, face.side << face.axis);
        Vec3 centre = g.corner(lo);
        const int a1 = (face.axis + 1) % 3, a2 = (face.axis + 2) % 3;
        centre[a1] = g.origin[a1] + (lo[size_t(a1)] + 0.5) * g.h;
        centre[a2] = g.origin[a2] + (lo[size_t(a2)] + 0.5) * g.h;
        const bool joined = (evaluate(tape, centre) > 0) == (f[size_t(face.corners[0])] > 0);
        if (joined) {
          join(edge[0], edge[1]);
          join(edge[2], edge[3]);
        } else {
          join(edge[3], edge[0]);
          join(edge[1], edge[2]);
        }
      }
    }
    std::array<std::int8_t, 12> loop_of_root;
    loop_of_root.fill(-1);
    for (int e = 0; e < 12; ++e) {
      if ((f[size_t(edge_corner(e, 0))] > 0) == (f[size_t(edge_corner(e, 1))] > 0)) continue;
      const int r = find(parent, e);
      if (loop_of_root[size_t(r)] < 0) loop_of_root[size_t(r)] = std::int8_t(v.loops++);
      v.vertex_of_edge[size_t(e)] = loop_of_root[size_t(r)];
    }
  });
  out.hidden = std::any_of(hidden.begin(), hidden.end(), [](char h) { return h != 0; });
  std::uint32_t total = 0;
  for (CellVertices& v : loops) {
    v.first = total;
    total += std::uint32_t(v.loops);
  }
  auto index_of = [&](const Cell& c) -> std::optional<std::size_t> {
    const std::uint64_t k = key(c);
    const auto it = std::lower_bound(cells.begin(), cells.end(), k,
                                     [](const Cell& a, std::uint64_t b) { return key(a) < b; });
    if (it == cells.end() || key(*it) != k) return std::nullopt;
    return std::size_t(it - cells.begin());
  };
  // Each grid edge the surface crosses, once: a cell finds the roots on the three edges from its
  // lowest corner, which the up to four cells around each edge share.
  std::vector<std::array<EdgePoint, 3>> roots(cells.size());
  tbb::parallel_for(std::size_t{0}, cells.size(), [&](std::size_t i) {
    if (loops[i].loops == 0) return;
    for (int axis = 0; axis < 3; ++axis) {
      const int e = edge_of(axis, 0, 0);
      if (loops[i].vertex_of_edge[size_t(e)] < 0) continue;
      roots[i][size_t(axis)] = edge_point(
          tape, g.corner(cells[i]), g.corner(corner_of(cells[i], edge_corner(e, 1))), values[i][0]);
    }
  });
  TriangleMesh& mesh = out.mesh;
  mesh.positions.resize(total);
  mesh.normals.resize(total);
  std::vector<double> vertex_error(cells.size(), 0);
  // Vertices: each loop's quadratic error function over its edges' roots; then onto the
  // surface.
  tbb::parallel_for(std::size_t{0}, cells.size(), [&](std::size_t i) {
    const CellVertices& v = loops[i];
    if (v.loops == 0) return;
    const Cell& c = cells[i];
    std::array<std::vector<EdgePoint>, 12> points;
    for (int e = 0; e < 12; ++e) {
      const int loop = v.vertex_of_edge[size_t(e)];
      if (loop < 0) continue;
      // The edge's root, from the cell whose lowest corner the edge starts at (a cell around a
      // crossed edge is always one of the cells: interval arithmetic cannot clear it).
      const int a = edge_corner(e, 0);
      const Cell owner = corner_of(c, a);
      const auto k = owner == c ? std::optional<std::size_t>(i) : index_of(owner);
      points[size_t(loop)].push_back(k ? roots[*k][size_t(e / 4)]
                                       : edge_point(tape, g.corner(owner),
                                                    g.corner(corner_of(c, edge_corner(e, 1))),
                                                    values[i][size_t(a)]));
    }
    const Box box{g.corner(c), g.corner(corner_of(c, 7))};
    for (int loop = 0; loop < v.loops; ++loop) {
      const std::vector<EdgePoint>& pts = points[size_t(loop)];
      Vec3 mass{0, 0, 0};
      Vec3 x = qef_vertex(pts, box, mass);
      // Onto the surface, so that a face's vertices lie in the planes of the faces of the shape
      // they stand for (split_folds needs them there): along the gradient, or where that line
      // misses it (outside a curved sharp edge, past both faces), towards the mass point of the
      // edges' roots, which lies on the solid's side of the edge.
      Vec3 n = outward(tape, x);
      double d = 0;
      for (const bool along_gradient : {true, false}) {
        const Vec3 dir = along_gradient ? n : mass - x;
        if (!(length(dir) > 0)) continue;
        const Vec3 u = normalize(dir);
        const auto t = nearest_root(tape, x, u, 2 * g.h);
        if (!t) {
          d = 2 * g.h;
          continue;
        }
        x = x + u * *t;
        d = 0;
        break;
      }
      const Vec3 m = outward(tape, x);
      if (length(m) > 0) n = m;
      if (!(length(n) > 0)) {
        for (const EdgePoint& p : pts) n += p.n;
        n = length(n) > 0 ? normalize(n) : Vec3{0, 0, 1};
      }
      mesh.positions[v.first + std::uint32_t(loop)] = x;
      mesh.normals[v.first + std::uint32_t(loop)] = n;
      vertex_error[i] = std::max(vertex_error[i], d);
    }
  });
  for (const double e : vertex_error) out.vertex_error = std::max(out.vertex_error, e);
  // Faces: a quad around each grid edge with a sign change, of the four cells' loops there,
  // emitted by the cell at the edge's lowest position; counter-clockwise seen from outside.
  std::vector<std::vector<std::array<std::uint32_t, 3>>> triangles(cells.size());
  tbb::parallel_for(std::size_t{0}, cells.size(), [&](std::size_t i) {
    const Cell& c = cells[i];
    for (int axis = 0; axis < 3; ++axis) {
      const int e = edge_of(axis, 1, 1);
      const int lo = edge_corner(e, 0);
      const double f0 = values[i][size_t(lo)], f1 = values[i][size_t(edge_corner(e, 1))];
      if ((f0 > 0) == (f1 > 0)) continue;
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      Cell c1 = c, c2 = c, c3 = c;
      c1[size_t(a1)] += 1;
      c2[size_t(a1)] += 1;
      c2[size_t(a2)] += 1;
      c3[size_t(a2)] += 1;
      const auto i1 = index_of(c1), i2 = index_of(c2), i3 = index_of(c3);
      if (!i1 || !i2 || !i3) continue;  // at the grid's edge, which the padding keeps outside
      auto vertex = [&](std::size_t k, int edge) {
        return loops[k].first + std::uint32_t(loops[k].vertex_of_edge[size_t(edge)]);
      };
      std::array<std::uint32_t, 4> q = {vertex(i, e), vertex(*i1, edge_of(axis, 0, 1)),
                                        vertex(*i2, edge_of(axis, 0, 0)),
                                        vertex(*i3, edge_of(axis, 1, 0))};
      if (!(f0 > 0)) std::swap(q[1], q[3]);  // outside at the low end: the normal points back
      // The diagonal that follows the surface: across a sharp edge, the one along the edge,
      // whose midpoint lies on it, rather than the one that cuts the corner.
      const auto& p = mesh.positions;
      const auto& nn = mesh.normals;
      const double d02 = surface_distance(tape, (p[q[0]] + p[q[2]]) * 0.5,
                                          normalize(nn[q[0]] + nn[q[2]] + Vec3{0, 0, 1e-12}), g.h);
      const double d13 = surface_distance(tape, (p[q[1]] + p[q[3]]) * 0.5,
                                          normalize(nn[q[1]] + nn[q[3]] + Vec3{0, 0, 1e-12}), g.h);
      // Not a split with a face of three points in a line, or turned over (misshapen, against
      // its vertices' normals).
      const auto bad = [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) {
        return misshapen(p[x], p[y], p[z], nn[x] + nn[y] + nn[z]);
      };
      const bool bad02 = bad(q[0], q[1], q[2]) || bad(q[0], q[2], q[3]);
      const bool bad13 = bad(q[0], q[1], q[3]) || bad(q[1], q[2], q[3]);
      if (bad02 != bad13 ? bad13
                         : d02 < d13 || (d02 == d13 &&
                                         length(p[q[0]] - p[q[2]]) <= length(p[q[1]] - p[q[3]]))) {
        triangles[i].push_back({q[0], q[1], q[2]});
        triangles[i].push_back({q[0], q[2], q[3]});
      } else {
        triangles[i].push_back({q[0], q[1], q[3]});
        triangles[i].push_back({q[1], q[2], q[3]});
      }
    }
  });
  for (const auto& t : triangles) mesh.triangles.insert(mesh.triangles.end(), t.begin(), t.end());
  return out;
}

// The 13 directions of the axes and the face and cube diagonals, one of each opposite pair: lines
// along which a point's distance to the surface is searched besides its normal.
const std::array<Vec3, 13>& fixed_directions() {
  static const std::array<Vec3, 13> directions = [] {
    std::array<Vec3, 13> out;
    std::size_t k = 0;
    for (int x = -1; x <= 1; ++x)
      for (int y = -1; y <= 1; ++y)
        for (int z = -1; z <= 1; ++z)
          if (x > 0 || (x == 0 && y > 0) || (x == 0 && y == 0 && z > 0))
            out[k++] = normalize(Vec3{double(x), double(y), double(z)});
    return out;
  }();
  return directions;
}

// d, a point's distance to the surface along some line, or where that is above `bound`, the
// distance to a root within `bound` along one of 13 more fixed directions (axes, face and cube
// diagonals), if there is one. Along a face's normal, a point on a sharp edge's chamfer may see
// the far side of the shape first, which would refine the whole grid for an error that is not
// there.
double fixed_direction_distance(const Tape& tape, const Vec3& p, double d, double bound) {
  // Only whether a root lies within the bound matters: each direction is searched that far (a
  // short search, where interval root finding costs most), and the first one found ends it.
  for (const Vec3& w : fixed_directions()) {
    if (d <= bound) break;
    if (const auto t = nearest_root(tape, p, w, bound)) d = std::min(d, std::abs(*t));
  }
  return d;
}

// Whether F changes sign between p and p + s u or p − s u: the nearest root along u lies within s.
bool sign_change_within(const Tape& tape, const Vec3& p, const Vec3& u, double s) {
  const bool inside = evaluate(tape, p) > 0;
  return (evaluate(tape, p + u * s) > 0) != inside || (evaluate(tape, p - u * s) > 0) != inside;
}

// A sample point's distance to the surface along its face's normal u (surface_distance), or
// `near`, an upper bound, where F changes sign within `near` of it along u (0: always measured).
double probed_distance(const Tape& tape, const Vec3& p, const Vec3& u, double reach, double near) {
  if (near > 0 && sign_change_within(tape, p, u, near)) return near;
  return surface_distance(tape, p, u, reach);
}

// A point's distance to the surface (probed_distance), tighter than surface_distance where that
// is above `bound`.
double tight_distance(const Tape& tape, const Vec3& p, const Vec3& n, double reach, double bound,
                      double near) {
  return fixed_direction_distance(tape, p, probed_distance(tape, p, n, reach, near), bound);
}

// A face's sample points, its centroid and edge midpoints, and its unit normal; false for a
// degenerate face, whose distance counts as 0.
bool face_samples(const TriangleMesh& mesh, const std::array<std::uint32_t, 3>& t,
                  std::array<Vec3, 4>& points, Vec3& u) {
  const Vec3 &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]];
  const Vec3 n = cross(b - a, c - a);
  if (!(length(n) > 0)) return false;
  u = normalize(n);
  points = {(a + b + c) / 3.0, (a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5};
  return true;
}

// The largest distance of a face's centroid or edge midpoints to the surface (tight_distance:
// `near` where probing shows no more), or, once one is above `bound`, that one's: the face fails,
// and by how much no longer matters.
double face_distance(const Tape& tape, const TriangleMesh& mesh,
                     const std::array<std::uint32_t, 3>& t, double reach, double bound,
                     double near) {
  std::array<Vec3, 4> points;
  Vec3 u;
  if (!face_samples(mesh, t, points, u)) return 0;
  double worst = 0;
  for (const Vec3& p : points) {
    worst = std::max(worst, tight_distance(tape, p, u, reach, bound, near));
    if (worst > bound) break;
  }
  return worst;
}

// The largest face distance, exact: a face at `near` may be nearer (probed_distance), and where
// that is the largest, those faces are measured.
double exact_largest(const Tape& tape, const TriangleMesh& mesh, std::vector<double>& distance,
                     double reach, double bound, double near) {
  const auto largest = [&] {
    return distance.empty() ? 0.0 : *std::max_element(distance.begin(), distance.end());
  };
  if (largest() != near) return largest();
  tbb::parallel_for(std::size_t{0}, distance.size(), [&](std::size_t i) {
    if (distance[i] == near)
      distance[i] = face_distance(tape, mesh, mesh.triangles[i], reach, bound, 0);
  });
  return largest();
}

// A grid's faces measured as far as polygonize's choice needs: the largest face_distance, and
// whether at most one face in kFewFailing fails (then each face's face_distance, for bisection).
// Every sample point is first measured along its face's normal (probed_distance: `near` where a
// sign change shows it that near); the 13 fixed directions, which
// cost 26 root searches where no root within the bound is found, are then searched at the points
// above the bound, farthest first, in batches, only until that choice is made: the farthest
// point they leave above the bound is the largest distance, and once more than one face in
// kFewFailing is known to fail the rest cannot change the choice. A coarse grid whose faces
// mostly fail is searched at about one face in kFewFailing, not at every point. The same result
// for any number of threads.
struct FaceMeasure {
  std::vector<double> distance;  // each face's face_distance where `exact`
  double worst = 0;              // the largest face_distance
  bool exact = true;             // false: more than one face in kFewFailing fails
};
FaceMeasure measure_faces(const Tape& tape, const TriangleMesh& mesh, double reach, double bound,
                          double near) {
  const std::size_t faces = mesh.triangles.size();
  std::vector<std::array<double, 4>> along(faces);
  tbb::parallel_for(std::size_t{0}, faces, [&](std::size_t i) {
    std::array<Vec3, 4> points;
    Vec3 u;
    along[i] = {0, 0, 0, 0};
    if (face_samples(mesh, mesh.triangles[i], points, u))
      for (std::size_t k = 0; k < 4; ++k)
        along[i][k] = probed_distance(tape, points[k], u, reach, near);
  });
  // The points above the bound (4 face + k), farthest first.
  std::vector<std::pair<double, std::size_t>> above;
  for (std::size_t i = 0; i < faces; ++i)
    for (std::size_t k = 0; k < 4; ++k)
      if (along[i][k] > bound) above.push_back({along[i][k], 4 * i + k});
  std::sort(above.begin(), above.end(), [](const auto& x, const auto& y) {
    return x.first > y.first || (x.first == y.first && x.second < y.second);
  });
  FaceMeasure out;
  std::vector<char> failing(faces, 0);
  std::size_t failing_faces = 0;
  bool worst_known = false;
  // Enough points for both threads, few past the choice.
  constexpr std::size_t kBatch = 256;
  std::vector<double> searched;
  for (std::size_t next = 0; next < above.size(); next += kBatch) {
    if (worst_known && failing_faces * kFewFailing > faces) {
      out.exact = false;
      break;
    }
    const std::size_t count = std::min(kBatch, above.size() - next);
    searched.resize(count);
    tbb::parallel_for(std::size_t{0}, count, [&](std::size_t j) {
      const std::size_t i = above[next + j].second / 4, k = above[next + j].second % 4;
      std::array<Vec3, 4> points;
      Vec3 u;
      face_samples(mesh, mesh.triangles[i], points, u);
      searched[j] = fixed_direction_distance(tape, points[k], above[next + j].first, bound);
    });
    for (std::size_t j = 0; j < count; ++j) {
      const std::size_t i = above[next + j].second / 4, k = above[next + j].second % 4;
      along[i][k] = searched[j];
      if (searched[j] <= bound) continue;
      if (!worst_known) out.worst = searched[j];
      worst_known = true;
      if (!failing[i]) ++failing_faces;
      failing[i] = 1;
    }
  }
  if (!out.exact) return out;
  out.distance.resize(faces);
  for (std::size_t i = 0; i < faces; ++i)
    out.distance[i] = *std::max_element(along[i].begin(), along[i].end());
  out.worst = exact_largest(tape, mesh, out.distance, reach, bound, near);
  return out;
}

// The point of the surface nearest p among the roots along n, the gradient and 13 fixed
// directions (axes, face and cube diagonals), within reach; none if there is none.
std::optional<Vec3> nearest_surface_point(const Tape& tape, const Vec3& p, const Vec3& n,
                                          double reach) {
  std::vector<Vec3> directions{n, outward(tape, p)};
  directions.insert(directions.end(), fixed_directions().begin(), fixed_directions().end());
  std::optional<Vec3> best;
  double best_t = reach;
  for (const Vec3& d : directions) {
    if (!(length(d) > 0)) continue;
    const Vec3 u = normalize(d);
    if (const auto t = nearest_root(tape, p, u, best_t); t && std::abs(*t) < best_t) {
      best_t = std::abs(*t);
      best = p + u * *t;
    }
  }
  return best;
}

// How far inside the surface p lies to first order, F/|∇F| (negative outside): exact where F is
// a plane's signed distance.
double first_order_depth(const Tape& tape, const Vec3& p) {
  const double g = length(gradient(tape, p));
  return g > 0 ? evaluate(tape, p) / g : 0;
}

// Where a mesh edge (a, b) crosses a sharp edge of the shape (its ends on two faces, their normals
// apart), the point of the sharp edge between them: where the tangent planes at a and b meet the
// plane through a and b that holds their mean normal. None where the planes are near parallel,
// the point is not between a and b, or the surface is not there (a smooth bend, whose tangent
// planes meet off it).
std::optional<Vec3> fold_point(const Tape& tape, const Vec3& pa, const Vec3& na, const Vec3& pb,
                               const Vec3& nb, double tolerance) {
  if (dot(na, nb) > kFoldCos) return std::nullopt;
  // The tangent planes n·x = d through the surface near each end, where a vertex a root search
  // left a little off it (first order, exact for a plane).
  const double da = dot(na, pa) + first_order_depth(tape, pa);
  const double db = dot(nb, pb) + first_order_depth(tape, pb);
  const Vec3 ab = pb - pa;
  // Each end off the other's tangent plane: an end already on the sharp edge needs no point
  // beside it (which would make a face of three points on the edge).
  const double off = 0.05 * length(ab);
  if (std::abs(dot(nb, pa) - db) <= off || std::abs(dot(na, pb) - da) <= off) return std::nullopt;
  const Vec3 side = cross(ab, na + nb);
  if (!(length(side) > 0)) return std::nullopt;
  const Vec3 s = normalize(side);
  // Cramer's rule for na·x = da, nb·x = db, s·x = s·pa.
  const double det = dot(na, cross(nb, s));
  if (std::abs(det) < 0.25) return std::nullopt;
  const double ds = dot(s, pa);
  const Vec3 x = (cross(nb, s) * da + cross(s, na) * db + cross(na, nb) * ds) / det;
  const double t = dot(x - pa, ab) / dot(ab, ab);
  if (!(t > 0.05 && t < 0.95)) return std::nullopt;
  // On the surface: F changes sign within the tolerance along the mean normal.
  if (!sign_change_within(tape, x, normalize(na + nb), tolerance)) return std::nullopt;
  return x;
}

// The corner where three planes (points p, normals n) pairwise apart meet, if the surface is
// there; none where they are near parallel or it is not.
std::optional<Vec3> corner_point(const Tape& tape, const std::array<Vec3, 3>& p,
                                 const std::array<Vec3, 3>& n, double tolerance) {
  for (int k = 0; k < 3; ++k)
    if (dot(n[size_t(k)], n[size_t(k + 1) % 3]) > kFoldCos) return std::nullopt;
  // Cramer's rule for n_k·x = n_k·p_k.
  const double det = dot(n[0], cross(n[1], n[2]));
  if (std::abs(det) < 0.25) return std::nullopt;
  const Vec3 x = (cross(n[1], n[2]) * dot(n[0], p[0]) + cross(n[2], n[0]) * dot(n[1], p[1]) +
                  cross(n[0], n[1]) * dot(n[2], p[2])) /
                 det;
  if (!sign_change_within(tape, x, normalize(n[0] + n[1] + n[2]), tolerance)) return std::nullopt;
  return x;
}

// A closed mesh whose edges are split at a point in both faces that share them, so that it stays
// closed and 2-manifold, with the orientation kept.
class EdgeSplitter {
 public:
  explicit EdgeSplitter(TriangleMesh& m) : m_(m) {
    faces_of_.reserve(m.triangles.size() * 3 / 2);
    for (std::uint32_t i = 0; i < m.triangles.size(); ++i)
      for (int k = 0; k < 3; ++k)
        attach(m.triangles[i][size_t(k)], m.triangles[i][size_t(k + 1) % 3], i);
  }
  // The vertices opposite edge k of face t, (a, b) in its order: c in t and d in the other face
  // that shares the edge; none where the edge has one face only.
  std::optional<std::array<std::uint32_t, 2>> opposite(std::uint32_t t, int k) const {
    const auto u = beside(t, k);
    if (!u) return std::nullopt;
    const Face f = m_.triangles[t], g = m_.triangles[*u];
    int j = 0;
    while (g[size_t(j)] == f[size_t(k)] || g[size_t(j)] == f[size_t(k + 1) % 3]) ++j;
    return std::array<std::uint32_t, 2>{f[size_t(k + 2) % 3], g[size_t(j)]};
  }
  // The face that shares edge k of face t; none where the edge has one face only.
  std::optional<std::uint32_t> beside(std::uint32_t t, int k) const {
    const Face f = m_.triangles[t];
    const auto& pair = faces_of_.at(key(f[size_t(k)], f[size_t(k + 1) % 3]));
    const std::uint32_t u = pair[0] == t ? pair[1] : pair[0];
    if (u == kNone) return std::nullopt;
    return u;
  }
  // Splits face t = (a, b, c) at p (normal n) into (a, b, v), (b, c, v) and (c, a, v): the three
  // faces.
  std::array<std::uint32_t, 3> split_face(std::uint32_t t, const Vec3& p, const Vec3& n) {
    const Face f = m_.triangles[t];
    const std::uint32_t a = f[0], b = f[1], c = f[2];
    const std::uint32_t v = add_vertex(p, n);
    const auto t1 = std::uint32_t(m_.triangles.size()), t2 = t1 + 1;
    m_.triangles[t] = {a, b, v};
    m_.triangles.push_back({b, c, v});
    m_.triangles.push_back({c, a, v});
    replace(b, c, t, t1);
    replace(c, a, t, t2);
    faces_of_[key(b, v)] = {t, t1};
    faces_of_[key(c, v)] = {t1, t2};
    faces_of_[key(a, v)] = {t2, t};
    return {t, t1, t2};
  }
  // Splits edge k of face t, (a, b) in its order, at p (normal n): the four faces changed or
  // added, or none where the edge has one face only.
  std::optional<std::array<std::uint32_t, 4>> split(std::uint32_t t, int k, const Vec3& p,
                                                    const Vec3& n) {
    const auto cd = opposite(t, k);
    if (!cd) return std::nullopt;
    const std::uint32_t a = m_.triangles[t][size_t(k)], b = m_.triangles[t][size_t(k + 1) % 3];
    const std::uint32_t c = (*cd)[0], d = (*cd)[1], u = *beside(t, k);
    const std::uint32_t v = add_vertex(p, n);
    // t = (a, b, c) becomes (a, v, c) and t1 = (v, b, c); u = (b, a, d) becomes (b, v, d) and
    // u1 = (v, a, d): the orientation kept.
    const auto t1 = std::uint32_t(m_.triangles.size()), u1 = t1 + 1;
    m_.triangles[t] = {a, v, c};
    m_.triangles.push_back({v, b, c});
    m_.triangles[u] = {b, v, d};
    m_.triangles.push_back({v, a, d});
    faces_of_.erase(key(a, b));
    replace(b, c, t, t1);
    replace(a, d, u, u1);
    faces_of_[key(a, v)] = {t, u1};
    faces_of_[key(v, b)] = {t1, u};
    faces_of_[key(v, c)] = {t, t1};
    faces_of_[key(v, d)] = {u, u1};
    return std::array<std::uint32_t, 4>{t, t1, u, u1};
  }

 private:
  using Face = std::array<std::uint32_t, 3>;
  static constexpr std::uint32_t kNone = ~std::uint32_t{0};
  static std::uint64_t key(std::uint32_t a, std::uint32_t b) {
    return (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
  }
  std::uint32_t add_vertex(const Vec3& p, const Vec3& n) {
    m_.positions.push_back(p);
    m_.normals.push_back(n);
    return std::uint32_t(m_.positions.size() - 1);
  }
  void attach(std::uint32_t a, std::uint32_t b, std::uint32_t face) {
    auto [it, fresh] = faces_of_.try_emplace(key(a, b), std::array<std::uint32_t, 2>{face, kNone});
    if (!fresh) it->second[1] = face;
  }
  void replace(std::uint32_t a, std::uint32_t b, std::uint32_t from, std::uint32_t to) {
    auto& f = faces_of_.at(key(a, b));
    (f[0] == from ? f[0] : f[1]) = to;
  }
  TriangleMesh& m_;
  std::unordered_map<std::uint64_t, std::array<std::uint32_t, 2>> faces_of_;  // each edge's faces
};

// Makes good the faces further than `error` from the surface by bisecting them, rather than by
// refining the whole grid: where few faces fail (chamfers along a sharp edge off the grid's axes,
// whose depth falls only as the cell), a failing face's longest edge is split at its midpoint
// moved onto the surface, in both faces that share it, so that the mesh stays closed and
// 2-manifold, until every face is within the bound. Sequential, in the faces' order: the same
// mesh for any number of threads. `distance` holds each face's face_distance, and is kept so for
// the faces the bisection adds and changes (a face is measured again only once it has changed).
// False, with the mesh half done, where a midpoint finds no surface within reach or the faces
// pass max_faces.
bool bisect_failing_faces(const Tape& tape, TriangleMesh& m, std::vector<double>& distance,
                          double error, double near, double reach, std::size_t max_faces) {
  EdgeSplitter splitter(m);
  std::deque<std::uint32_t> failing;
  for (std::uint32_t i = 0; i < m.triangles.size(); ++i)
    if (distance[i] > error) failing.push_back(i);
  // Whether distance[i] is that of face i as it is now.
  std::vector<char> measured(m.triangles.size(), 1);
  while (!failing.empty()) {
    const std::uint32_t t = failing.front();
    failing.pop_front();
    if (!measured[t]) distance[t] = face_distance(tape, m, m.triangles[t], reach, error, near);
    measured[t] = 1;
    if (distance[t] <= error) continue;
    if (m.triangles.size() + 2 > max_faces) return false;
    // The longest edge, k: (a, b) in the face's order.
    const auto& f = m.triangles[t];
    int k = 0;
    for (int j = 1; j < 3; ++j)
      if (length(m.positions[f[size_t(j)]] - m.positions[f[size_t(j + 1) % 3]]) >
          length(m.positions[f[size_t(k)]] - m.positions[f[size_t(k + 1) % 3]]))
        k = j;
    const std::uint32_t a = f[size_t(k)], b = f[size_t(k + 1) % 3];
    const Vec3 n = m.normals[a] + m.normals[b];
    const auto p = nearest_surface_point(tape, (m.positions[a] + m.positions[b]) * 0.5,
                                         length(n) > 0 ? normalize(n) : Vec3{0, 0, 1}, reach);
    if (!p || length(m.positions[a] - m.positions[b]) < 1e-9 * reach) return false;
    const Vec3 nv = outward(tape, *p);
    const auto changed = splitter.split(t, k, *p, length(nv) > 0 ? nv : normalize(n));
    if (!changed) return false;
    // Each changed face is measured again when it is taken from the queue.
    distance.resize(m.triangles.size(), std::numeric_limits<double>::infinity());
    measured.resize(m.triangles.size(), 0);
    for (std::uint32_t face : *changed) {
      measured[face] = 0;
      failing.push_back(face);
    }
  }
  return true;
}

// Splits each mesh edge that crosses a sharp edge of the shape at the sharp edge's point between
// its ends (fold_point), in both faces that share it, until no edge crosses one: a chamfer
// face (a cell that sees one face of an edge off the grid's axes) becomes two faces, one on each
// side, meeting on the sharp edge. Sequential, in the faces' order: the same mesh for any
// number of threads. At most `max_splits` splits.
void split_folds(const Tape& tape, TriangleMesh& m, double tolerance, std::size_t max_splits) {
  // A smooth surface's neighbouring normals are near: most meshes have no edge to split.
  const bool any = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, m.triangles.size()), false,
      [&](const tbb::blocked_range<std::size_t>& range, bool found) {
        for (std::size_t i = range.begin(); i != range.end() && !found; ++i)
          for (int k = 0; k < 3 && !found; ++k)
            found = dot(m.normals[m.triangles[i][size_t(k)]],
                        m.normals[m.triangles[i][size_t(k + 1) % 3]]) <= kFoldCos;
        return found;
      },
      [](bool a, bool b) { return a || b; });
  if (!any) return;
  EdgeSplitter splitter(m);
  std::deque<std::uint32_t> queue(m.triangles.size());
  std::iota(queue.begin(), queue.end(), 0);
  std::size_t splits = 0;
  while (!queue.empty() && splits < max_splits) {
    const std::uint32_t t = queue.front();
    queue.pop_front();
    bool done = false;
    for (int k = 0; k < 3 && !done; ++k) {
      const std::uint32_t a = m.triangles[t][size_t(k)], b = m.triangles[t][size_t(k + 1) % 3];
      const auto x =
          fold_point(tape, m.positions[a], m.normals[a], m.positions[b], m.normals[b], tolerance);
      if (!x) continue;
      // The four faces it would make, none misshapen: a fold point at a corner may lie beyond
      // the faces beside the edge.
      const auto cd = splitter.opposite(t, k);
      if (!cd) continue;
      const auto& p = m.positions;
      const Vec3 &pa = p[a], &pb = p[b], &pc = p[(*cd)[0]], &pd = p[(*cd)[1]];
      if (misshapen(tape, pa, *x, pc) || misshapen(tape, *x, pb, pc) ||
          misshapen(tape, pb, *x, pd) || misshapen(tape, *x, pa, pd))
        continue;
      const Vec3 nv = outward(tape, *x);
      const auto changed =
          splitter.split(t, k, *x, length(nv) > 0 ? nv : normalize(m.normals[a] + m.normals[b]));
      if (!changed) continue;
      ++splits;
      for (std::uint32_t face : *changed) queue.push_back(face);
      done = true;
    }
    if (done) continue;
    // A corner: where the planes of the three faces beside this one meet (a face whose three
    // edges are on three sharp edges, each beside a face of the shape), the face split in three.
    const auto f = m.triangles[t];
    const auto& p = m.positions;
    std::array<Vec3, 3> plane_point, plane_normal;
    bool planes = true;
    for (int k = 0; k < 3 && planes; ++k) {
      const auto u = splitter.beside(t, k);
      if (!u) {
        planes = false;
        break;
      }
      const auto& g = m.triangles[*u];
      const Vec3 n = cross(p[g[1]] - p[g[0]], p[g[2]] - p[g[0]]);
      planes = length(n) > 0;
      if (planes) {
        plane_point[size_t(k)] = p[g[0]];
        plane_normal[size_t(k)] = normalize(n);
      }
    }
    if (!planes) continue;
    const auto x = corner_point(tape, plane_point, plane_normal, tolerance);
    if (!x || misshapen(tape, p[f[0]], p[f[1]], *x) || misshapen(tape, p[f[1]], p[f[2]], *x) ||
        misshapen(tape, p[f[2]], p[f[0]], *x))
      continue;
    const Vec3 nv = outward(tape, *x);
    ++splits;
    for (std::uint32_t face : splitter.split_face(t, *x, length(nv) > 0 ? nv : m.normals[f[0]]))
      queue.push_back(face);
  }
}

}  // namespace

double distance_along(const Tape& tape, const Vec3& p, const Vec3& d, double reach) {
  const auto t = nearest_root(tape, p, d, reach);
  return t ? std::min(std::abs(*t), reach) : reach;
}

double surface_distance(const Tape& tape, const Vec3& p, const Vec3& n, double reach) {
  // A point on a sharp edge to round-off, whose normal lies in the other face: F is zero along
  // that line, and the search would report its far end. A sign change within a hair along one
  // of the fixed directions shows the surface there.
  const double hair = 1e-9 * reach;
  if (std::abs(evaluate(tape, p)) <= hair * length(gradient(tape, p)))
    for (const Vec3& w : fixed_directions())
      if (sign_change_within(tape, p, w, hair)) return hair;
  double d = distance_along(tape, p, n, reach);
  if (d < reach) return d;
  const Vec3 g = outward(tape, p);
  for (const Vec3& w : {g, n + g, n - g})
    if (length(w) > 0) d = std::min(d, distance_along(tape, p, normalize(w), reach));
  for (int k = 0; k < 3 && d >= reach; ++k) {
    Vec3 e{0, 0, 0};
    e[k] = 1;
    for (const Vec3& w : {e, n + e, n - e})
      if (length(w) > 0) d = std::min(d, distance_along(tape, p, normalize(w), reach));
  }
  return d;
}

TriangleMesh polygonize(const Tape& tape, const PolygonizeOptions& options,
                        PolygonizeReport* report) {
  if (!(options.error > 0) || !std::isfinite(options.error))
    throw PolygonizeError(fmt::format("the error bound must be > 0 (got {:g})", options.error));
  if (!tape.bounds.bounded) throw PolygonizeError("the shape is unbounded");
  const Box& bounds = tape.bounds.box;
  if (bounds.empty())
    throw PolygonizeError("the shape is empty (its function is positive nowhere)");
  const Vec3 extent = bounds.extent();
  const double size = std::max({extent.x, extent.y, extent.z});
  PolygonizeReport r;
  const double first_h = size / std::max(options.first_cells, 1);
  double h = first_h;
  std::uint64_t previous_cells = 0;
  double growth = 4;     // surface cells of this grid over the last one's, about
  double predicted = 0;  // this grid's face error as the last one predicted it
  bool smooth = true;    // the error has fallen as the square of the cell
  for (;;) {
    Grid g;
    g.h = h;
    for (int k = 0; k < 3; ++k) {
      g.origin[k] = bounds.lo[k] - (1 + kGridShift) * h;
      const double cells = std::ceil((bounds.hi[k] - g.origin[k]) / h) + 1;
      if (cells > kMaxAxisCells)
        throw PolygonizeError(fmt::format(
            "an error bound of {:g} needs a grid of {:.3g} cells along an axis; at most {} are "
            "supported",
            options.error, cells, kMaxAxisCells));
      g.n[size_t(k)] = int(cells);
    }
    // Surface cells grow as the square of the cell's shrinking.
    if (options.max_cells > 0 && double(previous_cells) * growth > double(options.max_cells))
      throw PolygonizeError(fmt::format(
          "an error bound of {:g} needs about {:.3g} grid cells at the surface (cell {:.3g}); "
          "the limit is {}",
          options.error, double(previous_cells) * growth, h, options.max_cells));
    GridMesh gm = mesh_grid(tape, g, options.error);
    split_folds(tape, gm.mesh, kFoldTolerance * options.error, gm.mesh.triangles.size());
    ++r.grids;
    r.cell = h;
    r.cells = gm.cells;
    r.vertex_error = gm.vertex_error;
    const double near = kSignProbe * options.error;
    const FaceMeasure measured = measure_faces(tape, gm.mesh, 2 * h, options.error, near);
    const std::vector<double>& distance = measured.distance;
    r.face_error = measured.worst;
    previous_cells = std::max<std::uint64_t>(gm.cells, 1);
    if (!gm.hidden && !gm.mesh.triangles.empty()) {
      if (r.face_error <= options.error) {
        if (report) *report = r;
        return std::move(gm.mesh);
      }
      // Few failing faces: bisected where they fail (up to four times the faces, within the
      // memory budget), else the grid is refined.
      const auto failing = std::size_t(std::count_if(distance.begin(), distance.end(),
                                                     [&](double d) { return d > options.error; }));
      if (measured.exact && failing * kFewFailing <= distance.size()) {
        TriangleMesh bisected = gm.mesh;
        // Two faces a surface cell: the memory budget's count (kPolygonizeBytesPerCell).
        const std::size_t budget =
            options.max_cells > 0 ? std::size_t(2 * options.max_cells) : ~std::size_t{0};
        std::vector<double> bisected_distance = distance;
        if (bisect_failing_faces(tape, bisected, bisected_distance, options.error, near, 2 * h,
                                 std::min(4 * gm.mesh.triangles.size(), budget))) {
          r.face_error =
              exact_largest(tape, bisected, bisected_distance, 2 * h, options.error, near);
          r.bisected = bisected.triangles.size() - gm.mesh.triangles.size();
          if (report) *report = r;
          return bisected;
        }
      }
    }
    // On a smooth surface the faces' error falls as the square of the cell: the next cell is the
    // one that predicts kAimedError of the bound, between a quarter and 0.8 of this one, so that
    // the mesh lands near the bound rather than up to four times below it (a halving's). A grid
    // that hides a piece of the shape, or holds none of it, is halved. Refuse now a bound whose
    // grid would pass the limit, rather than after meshing the grids on the way.
    // Where the error fell less than predicted (a curved sharp edge, whose chamfer shrinks only as
    // the cell, and unevenly with the grid's alignment), the cells are the first grid's halved
    // from then on, the next such below this one.
    if (predicted > 0 && r.face_error > 1.5 * predicted) smooth = false;
    double factor = 0.5;
    if (smooth && !gm.hidden && !gm.mesh.triangles.empty() && r.face_error > options.error)
      factor = std::clamp(std::sqrt(kAimedError * options.error / r.face_error), 0.25, 0.8);
    predicted = r.face_error * factor * factor;
    if (options.max_cells > 0 && r.face_error > options.error) {
      const double estimate = double(previous_cells) * r.face_error / options.error;
      if (estimate > double(options.max_cells))
        throw PolygonizeError(fmt::format(
            "an error bound of {:g} needs about {:.3g} grid cells at the surface (cell {:.3g}); "
            "the limit is {}",
            options.error, estimate, h * std::sqrt(options.error / r.face_error),
            options.max_cells));
    }
    const double next =
        smooth ? h * factor : first_h * std::exp2(-std::floor(std::log2(first_h / h) + 1e-9) - 1);
    growth = (h / next) * (h / next);
    h = next;
  }
}

}  // namespace nimbus
