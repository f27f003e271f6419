#pragma once
// Measuring a mesh against its shape's exact surface, for the tests and bench/mesh_error.cpp
// (docs/meshes.md): the distance from a point to a triangle, and points of the surface to
// measure from (the mesh's side of the Hausdorff distance is surface_distance, mesh/polygonize.h).

#include <cstdint>
#include <vector>

#include "nimbus/frep/tape.h"
#include "nimbus/math/vec3.h"

namespace nimbus {

// The distance from p to the triangle abc (its closest point, by the region of the triangle's
// plane p projects into).
double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// `count` points of the surface: the exact first roots of rays from a sphere around the bounds
// towards random points near the centre; the same points for the same seed.
std::vector<Vec3> surface_samples(const Tape& tape, int count, std::uint64_t seed = 17);

}  // namespace nimbus
