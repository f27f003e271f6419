#pragma once
// A shape's surface as a triangle mesh, to an error bound ε in scene units (docs/meshes.md):
// dual contouring on the cells of a grid that interval arithmetic prunes (frep/tape.h), with
// one vertex per loop of the surface through a cell (so the mesh is a closed 2-manifold), each
// vertex placed by its cell's quadratic error function (which keeps sharp edges and corners of
// CSG) and moved onto the surface, along the gradient, where it is more than ε/2 away. The grid
// is refined until every face's sample points lie within ε of the surface along the face's
// normal and no cell hides a piece of the shape between its corners. Parallel (oneTBB), and the
// same mesh for any number of threads.

#include <cstdint>
#include <stdexcept>

#include "nimbus/frep/tape.h"
#include "nimbus/mesh/mesh.h"

namespace nimbus {

// What one surface cell of the finest grid costs while meshing, with the two triangles and the
// vertex it adds: its key, corner values and loops, and the mesh's arrays (bytes, rounded up).
// max_cells for a memory budget is the budget over this.
inline constexpr std::uint64_t kPolygonizeBytesPerCell = 320;

struct PolygonizeOptions {
  double error = 0;             // ε > 0, scene units
  std::uint64_t max_cells = 0;  // refuse a grid estimated to need more surface cells; 0: no limit
  // Cells across the shape's largest extent in the first grid, which is refined from there: a
  // coarse preview of many small objects starts coarser.
  int first_cells = 16;
};

struct PolygonizeReport {
  double cell = 0;             // the last grid's cell size
  int grids = 0;               // grids meshed, coarse to fine
  std::uint64_t cells = 0;     // the last grid's cells that may hold the surface
  double vertex_error = 0;     // the largest vertex distance to the surface (exact root)
  double face_error = 0;       // the largest distance of a face's sample point to the surface
  std::uint64_t bisected = 0;  // faces added by bisecting failing faces of the last grid
};

// A request polygonize refuses: ε not positive, an empty or unbounded shape, or a grid past
// max_cells (the message gives the estimate).
struct PolygonizeError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

TriangleMesh polygonize(const Tape& tape, const PolygonizeOptions& options,
                        PolygonizeReport* report = nullptr);

// The distance from p to the surface along the line through p in direction d (unit), whichever
// way is nearer, by the exact first root; `reach` if there is none within it.
double distance_along(const Tape& tape, const Vec3& p, const Vec3& d, double reach);

// An upper bound on the distance from p to the surface: distance_along the direction n, or
// where that line misses the surface (a point on a face's plane just past a sharp edge), the
// least distance along the gradient, along n ± the gradient, along an axis or along n ± an axis.
double surface_distance(const Tape& tape, const Vec3& p, const Vec3& n, double reach);

}  // namespace nimbus
