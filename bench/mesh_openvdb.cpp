// OpenVDB's mesher (tools::volumeToMesh, isovalue 0, adaptivity 0) on a grid of nimbus's own
// function, for bench/mesh_side_by_side.py (docs/benchmarks.md, "Meshes side by side"):
//
//   mesh_openvdb SCENE VOXEL THREADS OUT.stl
//
// Voxel ijk holds the first-order distance estimate −F / |∇F| at ijk · VOXEL (negative inside,
// as OpenVDB's level sets are): volumeToMesh places its crossings by linear interpolation, which
// a distance is nearly and F (a quadric, a cube of one) is not. Only the 8³-voxel leaves that
// interval arithmetic cannot prove one-sided (their boxes grown by two voxels, so that both
// voxels of every crossing are sampled) are sampled, in parallel; the rest is a narrow band's
// background, ±3 voxels, whose sign signedFloodFill sets. Built on request only, as vdb_lookup
// is (OpenVDB's templates are slow to compile).

#include <openvdb/openvdb.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "mesh_anchor.h"
#include "nimbus/frep/tape.h"

namespace {

using namespace nimbus;
using openvdb::Coord;
using Leaf = openvdb::FloatTree::LeafNodeType;

// The leaves (by leaf coordinates: voxel ijk / Leaf::DIM) of [lo, hi) whose voxels, grown by two,
// interval arithmetic cannot prove one-sided; halving the block along each axis.
void collect_leaves(const Tape& tape, double h, const Coord& lo, const Coord& hi,
                    std::vector<Coord>& out) {
  const int dim = int(Leaf::DIM);
  Box box;
  for (int k = 0; k < 3; ++k) {
    box.lo[k] = (lo[k] * dim - 2) * h;
    box.hi[k] = (hi[k] * dim + 1) * h;
  }
  const Interval f = evaluate(tape, box);
  if (f.lo > 0 || f.hi <= 0) return;
  if (hi - lo == Coord(1, 1, 1)) {
    out.push_back(Coord(lo[0] * dim, lo[1] * dim, lo[2] * dim));
    return;
  }
  for (int o = 0; o < 8; ++o) {
    Coord a = lo, b = hi;
    bool empty = false;
    for (int k = 0; k < 3; ++k) {
      (o >> k & 1 ? a[k] : b[k]) = lo[k] + (hi[k] - lo[k] + 1) / 2;
      empty |= a[k] >= b[k];
    }
    if (!empty) collect_leaves(tape, h, a, b, out);
  }
}

TriangleMesh mesh_openvdb(const Tape& tape, double h) {
  const float background = float(3 * h);
  const Box& bounds = tape.bounds.box;
  Coord lo, hi;
  const int dim = int(Leaf::DIM);
  for (int k = 0; k < 3; ++k) {
    lo[k] = int(std::floor(std::floor(bounds.lo[k] / h - 2) / dim));
    hi[k] = int(std::floor(std::ceil(bounds.hi[k] / h + 2) / dim)) + 1;
  }
  std::vector<Coord> origins;
  collect_leaves(tape, h, lo, hi, origins);
  std::vector<std::unique_ptr<Leaf>> leaves(origins.size());
  tbb::parallel_for(std::size_t{0}, origins.size(), [&](std::size_t i) {
    auto leaf = std::make_unique<Leaf>(origins[i], background);
    for (openvdb::Index n = 0; n < Leaf::SIZE; ++n) {
      const Coord ijk = leaf->offsetToGlobalCoord(n);
      const Vec3 p{ijk.x() * h, ijk.y() * h, ijk.z() * h};
      const double f = evaluate(tape, p), g = length(gradient(tape, p));
      const double d = g > 0 ? std::clamp(-f / g, -3 * h, 3 * h) : (f > 0 ? -3 * h : 3 * h);
      leaf->setValueOn(n, float(d));
    }
    leaves[i] = std::move(leaf);
  });
  openvdb::FloatGrid grid(background);
  grid.setTransform(openvdb::math::Transform::createLinearTransform(h));
  for (auto& leaf : leaves) grid.tree().addLeaf(leaf.release());
  openvdb::tools::signedFloodFill(grid.tree());
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(grid, points, triangles, quads, 0.0, 0.0);
  TriangleMesh m;
  m.positions.reserve(points.size());
  for (const auto& p : points) m.positions.push_back({p.x(), p.y(), p.z()});
  m.triangles.reserve(triangles.size() + 2 * quads.size());
  for (const auto& t : triangles) m.triangles.push_back({t[0], t[1], t[2]});
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  openvdb::initialize();
  return mesh_anchor::run(argc, argv, "mesh_openvdb", mesh_openvdb);
}
