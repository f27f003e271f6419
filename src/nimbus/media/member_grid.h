#pragma once
// Which index-matched medium objects may hold a point (issue 26): a uniform grid over their
// bounds whose cells list, in ascending order, the objects whose bounds meet them. A point's
// lookup (medium_field.h) looks at its cell's objects only, so its cost follows the objects
// near the point, not the number in the scene. The grid has about kMemberGridCellsPerObject
// cells per object, coarser where the lists would exceed member_grid_max_entries in all.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "nimbus/frep/quadric.h"
#include "nimbus/frep/tape.h"
#include "nimbus/math/box.h"

namespace nimbus {

inline constexpr double kMemberGridCellsPerObject = 16;
// A grid has at most this many times its target of cells (kMemberGridCellsPerObject per object).
inline constexpr double kMemberGridMaxCellsPerTarget = 2;

// The most entries the cells' lists may hold in all for `objects` objects (puffs of similar
// sizes list about 170 per object; 2^24 at most, 64 MiB); a grid that would hold more is made
// coarser.
constexpr std::size_t member_grid_max_entries(std::size_t objects) {
  const std::size_t entries = (std::size_t{1} << 16) + 1024 * objects;
  return entries < (std::size_t{1} << 24) ? entries : std::size_t{1} << 24;
}

// Object k's function where it is one quadric (its tape a single instruction, as for a sphere or
// an ellipsoid puff), with its medium: a lookup evaluates it here, beside the boxes, rather than
// through the object and its tape, which a random point reaches from memory (issue 26).
struct GridQuadric {
  Quadric quadric;
  std::int32_t medium = -1;
  bool single = false;  // false: evaluate the object's tape
};

// Object i's bounds and, where it is one quadric, its function, in two cache lines: a lookup
// tests the box and evaluates the quadric from one record.
struct alignas(64) GridObject {
  Box bounds;
  Quadric quadric;  // where single
};
static_assert(sizeof(GridObject) == 128);

struct MemberGrid {
  Box box;  // the union of the objects' bounds; empty: no objects
  std::array<int, 3> cells{0, 0, 0};
  Vec3 inv_cell{0, 0, 0};            // cells per unit length, per axis
  std::vector<std::uint32_t> begin;  // cell c's objects: members[begin[c], begin[c + 1])
  std::vector<std::int32_t> members;
  std::vector<GridObject> objects;
  std::vector<std::int32_t> medium;  // object i's medium
  std::vector<std::uint8_t> single;  // whether object i is its quadric

  std::size_t bytes() const {
    return sizeof(MemberGrid) + begin.size() * sizeof(std::uint32_t) +
           members.size() * sizeof(std::int32_t) + objects.size() * sizeof(GridObject) +
           medium.size() * sizeof(std::int32_t) + single.size();
  }
  // The cell along axis k of coordinate v, clamped into the grid. Monotonic in v, so the
  // cells of an object's bounds hold every point inside them.
  int cell(int k, double v) const {
    const double c = (v - box.lo[k]) * inv_cell[k];
    return c <= 0 ? 0 : c >= cells[k] - 1 ? cells[k] - 1 : static_cast<int>(c);
  }
};

// The grid over `bounds` (object i's conservative bounds), with each object's `quadrics`.
MemberGrid build_member_grid(std::span<const Box> bounds, std::span<const GridQuadric> quadrics);

// What a grid keeps of an object whose function is `tape` and whose medium is `medium`.
GridQuadric grid_quadric(const Tape& tape, int medium);

// The most memory that building the grid over `objects` objects takes, whatever their bounds:
// what the memory estimate charges (render/memory_estimate.h).
std::size_t member_grid_max_bytes(std::size_t objects);

// The objects whose bounds may hold x, ascending (none outside the grid's box).
inline std::span<const std::int32_t> members_at(const MemberGrid& grid, const Vec3& x) {
  if (!grid.box.contains(x)) return {};
  const std::size_t c =
      (std::size_t(grid.cell(2, x.z)) * grid.cells[1] + grid.cell(1, x.y)) * grid.cells[0] +
      grid.cell(0, x.x);
  return {grid.members.data() + grid.begin[c], grid.members.data() + grid.begin[c + 1]};
}

}  // namespace nimbus
