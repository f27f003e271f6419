#pragma once
// A triangle mesh of a shape's surface (mesh/polygonize.h): positions, outward unit normals from
// the exact gradient, and counter-clockwise triangles seen from outside. Plain data, with the
// measures the tests and `nimbus export-mesh` report: enclosed volume, area, and the topology
// (watertight, 2-manifold, Euler characteristic, components).

#include <array>
#include <cstdint>
#include <vector>

#include "nimbus/math/vec3.h"

namespace nimbus {

struct TriangleMesh {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;  // one per position
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

// Appends b to a (b's indices shifted).
void append(TriangleMesh& a, const TriangleMesh& b);

// The volume a closed, outward-oriented mesh encloses (the divergence theorem over its
// triangles), and its area.
double enclosed_volume(const TriangleMesh& mesh);
double surface_area(const TriangleMesh& mesh);

struct MeshTopology {
  bool watertight = false;  // every edge is used by exactly two triangles, in opposite directions
  bool manifold = false;    // watertight, and the triangles around every vertex form one fan
  long euler = 0;           // V − E + F over the vertices the triangles use
  int components = 0;       // connected through shared vertices
};
MeshTopology mesh_topology(const TriangleMesh& mesh);

}  // namespace nimbus
