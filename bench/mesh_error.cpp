// A mesh's error against a scene object's exact surface, whoever made the mesh (nimbus
// export-mesh, libfive, OpenVDB, CGAL): for bench/mesh_side_by_side.py (docs/benchmarks.md,
// "Meshes side by side").
//
//   mesh_error SCENE MESH.stl [--object I] [--samples N]
//
// prints one JSON line: triangles, distinct vertices, and three distances, all in scene units:
//   vertex_error  the largest distance of a mesh vertex to the surface,
//   face_error    the largest distance of a triangle's centroid or edge midpoint to the surface,
//   hausdorff     the largest distance of N surface points (exact first roots of random rays) to
//                 the mesh; the two-sided Hausdorff distance is about max(face_error, hausdorff).
// Distances to the surface are exact roots (distance_along, mesh/polygonize.h) along the face's
// normal and 13 fixed directions, the least of them, within `reach` (four mean edges; a distance
// that equals it means "at least"); a mesh of over 200 000 triangles is measured on a sample of
// 200 000 of them (every k-th).

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "nimbus/math/constants.h"
#include "nimbus/mesh/measure.h"
#include "nimbus/mesh/polygonize.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace {

using namespace nimbus;

struct Triangle {
  Vec3 a, b, c;
};

// A binary STL's triangles (what libfive and nimbus both write).
std::vector<Triangle> read_stl(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  if (bytes.size() < 84) throw std::runtime_error(path + ": not a binary STL");
  std::uint32_t n = 0;
  std::memcpy(&n, bytes.data() + 80, 4);
  if (bytes.size() < 84 + 50 * std::uint64_t(n)) throw std::runtime_error(path + ": truncated");
  std::vector<Triangle> out(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    float f[12];
    std::memcpy(f, bytes.data() + 84 + 50 * std::uint64_t(i), sizeof f);
    out[i] = {{f[3], f[4], f[5]}, {f[6], f[7], f[8]}, {f[9], f[10], f[11]}};
  }
  return out;
}

// Triangles bucketed in a uniform grid by their boxes, for the distance from a point near the
// mesh: the cells within a radius, the radius doubled until a triangle lies within it.
class TriangleGrid {
 public:
  TriangleGrid(const std::vector<Triangle>& tris, double cell) : tris_(tris), cell_(cell) {
    for (std::uint32_t i = 0; i < tris.size(); ++i) {
      const Triangle& t = tris[i];
      const Vec3 lo = min(min(t.a, t.b), t.c), hi = max(max(t.a, t.b), t.c);
      for_cells(lo, hi, [&](const Key& k) { cells_[k].push_back(i); });
    }
  }
  double distance(const Vec3& p, double radius) const {
    for (;; radius *= 2) {
      double best = kInf;
      const Vec3 r{radius, radius, radius};
      for_cells(p - r, p + r, [&](const Key& k) {
        const auto found = cells_.find(k);
        if (found == cells_.end()) return;
        for (std::uint32_t i : found->second)
          best = std::min(best, point_triangle_distance(p, tris_[i].a, tris_[i].b, tris_[i].c));
      });
      if (best <= radius) return best;
    }
  }

 private:
  using Key = std::array<std::int64_t, 3>;
  template <class F>
  void for_cells(const Vec3& lo, const Vec3& hi, F&& f) const {
    Key a, b;
    for (int k = 0; k < 3; ++k) {
      a[k] = std::int64_t(std::floor(lo[k] / cell_));
      b[k] = std::int64_t(std::floor(hi[k] / cell_));
    }
    for (auto x = a[0]; x <= b[0]; ++x)
      for (auto y = a[1]; y <= b[1]; ++y)
        for (auto z = a[2]; z <= b[2]; ++z) f(Key{x, y, z});
  }
  const std::vector<Triangle>& tris_;
  double cell_;
  std::map<Key, std::vector<std::uint32_t>> cells_;
};

int run(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  int object = 0, samples = 2000;
  std::vector<std::string> files;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--object" && i + 1 < args.size())
      object = std::stoi(args[++i]);
    else if (args[i] == "--samples" && i + 1 < args.size())
      samples = std::stoi(args[++i]);
    else
      files.push_back(args[i]);
  }
  if (files.size() != 2) {
    std::fprintf(stderr, "usage: mesh_error SCENE MESH.stl [--object I] [--samples N]\n");
    return 2;
  }
  const Scene scene = compile_scene(load_scene_file(files[0]));
  const Tape& tape = scene.objects.at(size_t(object)).tape;
  const std::vector<Triangle> tris = read_stl(files[1]);
  double edge_sum = 0;
  for (const Triangle& t : tris) edge_sum += length(t.b - t.a);
  const double mean_edge = edge_sum / double(std::max<size_t>(tris.size(), 1));
  // A point's distance to the surface: the least exact root along its face's normal and 13 fixed
  // directions (axes, face and cube diagonals), each an upper bound. surface_distance alone stops
  // at the normal's root, which for a vertex on a sharp edge, rounded to floats, may be the far
  // side of the shape.
  const double reach = 4 * mean_edge;
  std::vector<Vec3> directions;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (x > 0 || (x == 0 && y > 0) || (x == 0 && y == 0 && z > 0))
          directions.push_back(normalize(Vec3{double(x), double(y), double(z)}));
  const auto distance = [&](const Vec3& p, const Vec3& u) {
    double d = distance_along(tape, p, u, reach);
    for (const Vec3& w : directions) d = std::min(d, distance_along(tape, p, w, reach));
    return d;
  };
  // Meshes of more than 200 000 triangles are measured on every k-th triangle.
  const size_t stride = std::max<size_t>(1, tris.size() / 200000);
  double vertex_error = 0, face_error = 0;
  for (size_t i = 0; i < tris.size(); i += stride) {
    const Triangle& t = tris[i];
    const Vec3 n = cross(t.b - t.a, t.c - t.a);
    const Vec3 u = length(n) > 0 ? normalize(n) : Vec3{0, 0, 1};
    for (const Vec3& v : {t.a, t.b, t.c}) vertex_error = std::max(vertex_error, distance(v, u));
    // The centroid and the edges' midpoints, as polygonize measures its own faces.
    for (const Vec3& p : {(t.a + t.b + t.c) / 3, (t.a + t.b) / 2, (t.b + t.c) / 2, (t.c + t.a) / 2})
      face_error = std::max(face_error, distance(p, u));
  }
  std::map<std::array<double, 3>, int> vertices;
  for (const Triangle& t : tris)
    for (const Vec3& v : {t.a, t.b, t.c}) vertices.emplace(std::array<double, 3>{v.x, v.y, v.z}, 0);
  // Cells about four mean edges across.
  const TriangleGrid grid(tris, 4 * mean_edge);
  double hausdorff = 0;
  for (const Vec3& p : surface_samples(tape, samples))
    hausdorff = std::max(hausdorff, grid.distance(p, mean_edge));
  std::printf(
      "{\"triangles\": %zu, \"vertices\": %zu, \"vertex_error\": %.6g, \"face_error\": %.6g, "
      "\"hausdorff\": %.6g, \"reach\": %.6g, \"stride\": %zu}\n",
      tris.size(), vertices.size(), vertex_error, face_error, hausdorff, reach, stride);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mesh_error: %s\n", e.what());
    return 2;
  }
}
