#include "nimbus/media/vdb_density.h"

#include <fmt/format.h>
#include <nanovdb/NanoVDB.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "nimbus/media/vdb_file.h"

namespace nimbus {
namespace {

using Grid = nanovdb::NanoGrid<float>;
using Coord = nanovdb::Coord;

constexpr double kInf = std::numeric_limits<double>::infinity();

// Trilinear interpolation in double of values that are floats blends them with rounding of a few
// ulps; range() widens its bounds by this relative margin so that they hold every value().
constexpr double kBlendRoundOff = 1e-14;

// An inclusive box of voxels.
struct Voxels {
  Coord lo, hi;
  bool empty() const { return lo[0] > hi[0] || lo[1] > hi[1] || lo[2] > hi[2]; }
  double count() const {
    return double(hi[0] - lo[0] + 1) * double(hi[1] - lo[1] + 1) * double(hi[2] - lo[2] + 1);
  }
  bool contains(const Voxels& o) const {
    for (int k = 0; k < 3; ++k)
      if (o.lo[k] < lo[k] || o.hi[k] > hi[k]) return false;
    return true;
  }
};

Voxels overlap(const Voxels& a, const Voxels& b) {
  return {
      Coord(std::max(a.lo[0], b.lo[0]), std::max(a.lo[1], b.lo[1]), std::max(a.lo[2], b.lo[2])),
      Coord(std::min(a.hi[0], b.hi[0]), std::min(a.hi[1], b.hi[1]), std::min(a.hi[2], b.hi[2]))};
}

// The voxels of a node of edge `dim` at `origin`.
Voxels node_voxels(const Coord& origin, int dim) {
  return {origin, origin + Coord(dim - 1)};
}

// The least and greatest value over a set of voxels, inactive ones counting as 0.
struct Extremes {
  double lo = kInf, hi = 0;
  void add(double v) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
};

// Whether every voxel under the node is active.
template <class Node>
bool fully_active(const Node& node) {
  if constexpr (Node::LEVEL == 0) {
    return node.valueMask().isOn();
  } else {
    for (std::uint32_t n = 0; n < Node::SIZE; ++n) {
      if (node.childMask().isOn(n)) {
        if (!fully_active(*node.data()->getChild(n))) return false;
      } else if (!node.valueMask().isOn(n)) {
        return false;
      }
    }
    return true;
  }
}

// Adds to `e` the values of the voxels `q` of a node at `origin` (q lies inside the node). Where
// the query covers a whole node, the node's own extrema answer (NanoVDB keeps the minimum and
// maximum of each node's active values); elsewhere the children and tiles it meets, down to the
// voxels of partly covered leaves.
template <class Node>
void add_node(const Node& node, const Coord& origin, const Voxels& q, Extremes& e) {
  if (q.contains(node_voxels(origin, Node::DIM))) {
    e.hi = std::max(e.hi, double(node.maximum()));
    // The minimum bounds from below only if no voxel of the node is inactive (0).
    if (e.lo > 0) e.lo = fully_active(node) ? std::min(e.lo, double(node.minimum())) : 0.0;
    return;
  }
  if constexpr (Node::LEVEL == 0) {
    for (int x = q.lo[0]; x <= q.hi[0]; ++x)
      for (int y = q.lo[1]; y <= q.hi[1]; ++y)
        for (int z = q.lo[2]; z <= q.hi[2]; ++z) e.add(node.getValue(Coord(x, y, z)));
  } else {
    using Child = typename Node::ChildNodeType;
    constexpr int kShift = Child::TOTAL, kLog2 = Node::LOG2DIM;
    const Coord a = (q.lo - origin) >> kShift, b = (q.hi - origin) >> kShift;
    for (int x = a[0]; x <= b[0]; ++x)
      for (int y = a[1]; y <= b[1]; ++y)
        for (int z = a[2]; z <= b[2]; ++z) {
          const std::uint32_t n = (x << (2 * kLog2)) | (y << kLog2) | z;
          if (node.childMask().isOn(n)) {
            const Coord child_origin = origin + (Coord(x, y, z) << kShift);
            add_node(*node.data()->getChild(n), child_origin,
                     overlap(q, node_voxels(child_origin, Child::DIM)), e);
          } else {
            e.add(node.valueMask().isOn(n) ? double(node.data()->getValue(n)) : 0.0);
          }
        }
  }
}

class VdbDensity final : public Density {
 public:
  VdbDensity(VdbFileGrid file, const Mat4& world_from_index)
      : file_(std::move(file)),
        grid_(static_cast<const Grid*>(file_.grid)),
        index_from_world_(inverse(world_from_index)) {
    const auto& bbox = grid_->tree().root().bbox();
    active_ = {bbox.min(), bbox.max()};
    if (file_.active_voxels == 0) active_ = {Coord(1), Coord(0)};
  }

  bool uses_F() const override { return false; }

  double value(const Vec3& x, double) const override {
    const Vec3 p = transform_point(index_from_world_, x);
    // Beyond one voxel of the active ones every blended voxel is 0 (and NaN stops here too).
    for (int k = 0; k < 3; ++k)
      if (!(p[k] > active_.lo[k] - 1.0 && p[k] < active_.hi[k] + 1.0)) return 0;
    const Vec3 base{std::floor(p.x), std::floor(p.y), std::floor(p.z)};
    const Vec3 t = p - base;
    const Coord ijk(int(base.x), int(base.y), int(base.z));
    // A fresh accessor per lookup: value() is called from every thread at once. Its cache still
    // serves the 8 corners, which mostly share a leaf.
    const auto acc = grid_->getAccessor();
    double c[2][2][2];
    // Two thirds of the stencils lie in one leaf (8³ voxels): one descent, then 8 reads.
    const int lx = ijk[0] & 7, ly = ijk[1] & 7, lz = ijk[2] & 7;
    const auto* leaf = lx < 7 && ly < 7 && lz < 7 ? acc.probeLeaf(ijk) : nullptr;
    if (leaf) {
      const std::uint32_t n = (lx << 6) | (ly << 3) | lz;
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
          for (int k = 0; k < 2; ++k) c[i][j][k] = leaf->getValue(n + (i << 6) + (j << 3) + k);
    } else {
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
          for (int k = 0; k < 2; ++k) c[i][j][k] = acc.getValue(ijk + Coord(i, j, k));
    }
    const auto lerp = [](double a, double b, double w) { return a + w * (b - a); };
    const double x0 =
        lerp(lerp(c[0][0][0], c[0][0][1], t.z), lerp(c[0][1][0], c[0][1][1], t.z), t.y);
    const double x1 =
        lerp(lerp(c[1][0][0], c[1][0][1], t.z), lerp(c[1][1][0], c[1][1][1], t.z), t.y);
    return lerp(x0, x1, t.x);
  }

  Interval range(const Box& box, const Interval&) const override {
    if (active_.empty() || box.empty()) return {0, 0};
    // The index-space hull of the box (the map is affine, so its corners span it).
    Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
    for (int c = 0; c < 8; ++c) {
      const Vec3 corner{c & 1 ? box.hi.x : box.lo.x, c & 2 ? box.hi.y : box.lo.y,
                        c & 4 ? box.hi.z : box.lo.z};
      const Vec3 p = transform_point(index_from_world_, corner);
      lo = min(lo, p);
      hi = max(hi, p);
    }
    // A value at p blends voxels floor(p) to floor(p) + 1 on each axis; the margin covers the
    // rounding of the two transforms, so that a point on a voxel boundary is never missed.
    Voxels q;
    bool beyond = false;  // the box reaches voxels outside the active ones, which are 0
    for (int k = 0; k < 3; ++k) {
      if (!(lo[k] <= hi[k])) return whole_grid();  // NaN from an unbounded box
      const double margin = 1e-9 * (1 + std::max(std::abs(lo[k]), std::abs(hi[k])));
      const double a = std::floor(lo[k] - margin), b = std::floor(hi[k] + margin) + 1;
      if (b < active_.lo[k] || a > active_.hi[k]) return {0, 0};
      beyond = beyond || a < active_.lo[k] || b > active_.hi[k];
      q.lo[k] = int(std::max(a, double(active_.lo[k])));
      q.hi[k] = int(std::min(b, double(active_.hi[k])));
    }
    Extremes e;
    if (beyond) e.add(0);
    add_root(q, e);
    return {e.lo * (1 - kBlendRoundOff), e.hi * (1 + kBlendRoundOff)};
  }

 private:
  Interval whole_grid() const {
    return {0, double(grid_->tree().root().maximum()) * (1 + kBlendRoundOff)};
  }

  // The root's table: tiles and upper nodes, each 4096³ voxels; the rest is background (0).
  void add_root(const Voxels& q, Extremes& e) const {
    const auto& root = grid_->tree().root();
    using Upper = nanovdb::NanoUpper<float>;
    // Coverage first: voxels of q that no entry covers are background, 0, which settles the
    // lower bound before any node is visited for it.
    double covered = 0;
    for (std::uint32_t i = 0; i < root.tileCount(); ++i) {
      const Voxels o = overlap(q, node_voxels(root.data()->tile(i)->origin(), Upper::DIM));
      if (!o.empty()) covered += o.count();
    }
    if (covered < q.count()) e.add(0);
    for (std::uint32_t i = 0; i < root.tileCount(); ++i) {
      const auto* tile = root.data()->tile(i);
      const Voxels o = overlap(q, node_voxels(tile->origin(), Upper::DIM));
      if (o.empty()) continue;
      if (tile->isChild())
        add_node(*root.data()->getChild(tile), tile->origin(), o, e);
      else
        e.add(tile->state ? double(tile->value) : 0.0);
    }
  }

  VdbFileGrid file_;
  const Grid* grid_;
  Mat4 index_from_world_;
  Voxels active_;  // the bounding box of the active voxels (empty when there are none)
};

}  // namespace

DensityPtr make_vdb_density(const VdbParams& params) {
  VdbFileGrid grid = read_vdb_file(params.file, params.grid, params.quantity, params.isolate_reader);
  const Mat4 world_from_index = params.transform * grid.world_from_index;
  const double det = determinant(world_from_index);
  if (!(std::abs(det) > 0) || !std::isfinite(det))
    throw VdbError("grid", fmt::format("{}: grid \"{}\" has a singular transform (determinant {})",
                                       params.file, params.grid, det));
  return std::make_shared<VdbDensity>(std::move(grid), world_from_index);
}

}  // namespace nimbus
