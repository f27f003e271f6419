// libfive's mesher on the shapes of bench/mesh_side_by_side.py, for the side-by-side of
// docs/benchmarks.md ("Meshes side by side"). Built by that script against a libfive built from
// source outside this repository; not part of nimbus's build.
//
//   mesh_libfive SHAPE MIN_FEATURE THREADS OUT.stl
//
// prints one JSON line: the seconds to mesh and write, and the triangles. The shapes are nimbus's
// functions negated (libfive is negative inside): a sphere, the free form of four perturbations of
// tests/mesh_test.cpp (F = Q0 + Σ w max(Qi, 0)³, the same quadrics), and a cylinder cut by
// two slabs.

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "libfive/render/brep/mesh.hpp"
#include "libfive/render/brep/region.hpp"
#include "libfive/render/brep/settings.hpp"
#include "libfive/tree/tree.hpp"

using libfive::Tree;

namespace {

// r² − |x − c|², nimbus's sphere (frep/primitives.h).
Tree sphere(double cx, double cy, double cz, double r) {
  const Tree x = Tree::X() - cx, y = Tree::Y() - cy, z = Tree::Z() - cz;
  return r * r - (square(x) + square(y) + square(z));
}

// 1 − Σ ((x − c) / r)², nimbus's ellipsoid.
Tree ellipsoid(double rx, double ry, double rz) {
  return 1.0 - (square(Tree::X() / rx) + square(Tree::Y() / ry) + square(Tree::Z() / rz));
}

Tree cube_of_positive(const Tree& q) {
  const Tree p = max(q, Tree(0.0));
  return p * p * p;
}

// nimbus's F, positive inside, and the box the shape lies in.
Tree shape(const std::string& name, double& extent) {
  if (name == "sphere") {
    extent = 1.1;
    return sphere(0, 0, 0, 1);
  }
  if (name == "freeform4") {
    extent = 1.3;
    return ellipsoid(0.95, 0.8, 0.8) + 0.8 * cube_of_positive(sphere(0.55, 0.45, 0.3, 0.45)) +
           0.8 * cube_of_positive(sphere(-0.6, 0.35, -0.2, 0.4)) -
           0.6 * cube_of_positive(sphere(0.1, -0.7, 0.5, 0.5)) +
           0.5 * cube_of_positive(sphere(0.0, 0.3, 0.75, 0.35));
  }
  if (name == "cylinder") {
    // r = 0.5 about z, cut to |z| <= 0.8: min of the cylinder's and the slab's functions.
    extent = 1.0;
    const Tree cyl = 0.25 - (square(Tree::X()) + square(Tree::Y()));
    const Tree slab = 0.64 - square(Tree::Z());
    return min(cyl, slab);
  }
  std::fprintf(stderr, "mesh_libfive: unknown shape %s\n", name.c_str());
  std::exit(2);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: mesh_libfive SHAPE MIN_FEATURE THREADS OUT.stl\n");
    return 2;
  }
  double extent = 1;
  const Tree f = -shape(argv[1], extent);
  libfive::BRepSettings settings;
  settings.min_feature = std::atof(argv[2]);
  settings.workers = unsigned(std::atoi(argv[3]));
  settings.alg = libfive::DUAL_CONTOURING;
  const libfive::Region<3> region({-extent, -extent, -extent}, {extent, extent, extent});
  const auto start = std::chrono::steady_clock::now();
  const auto mesh = libfive::Mesh::render(f, region, settings);
  if (!mesh || !mesh->saveSTL(argv[4])) return 1;
  // Meshing and writing, as nimbus export-mesh's own time counts them.
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("{\"seconds\": %.6f, \"triangles\": %zu}\n", seconds, mesh->branes.size());
  return 0;
}
