#include "nimbus/media/member_grid.h"

#include <algorithm>
#include <cmath>

namespace nimbus {
namespace {

// Cells per axis for about `target` cells in all, in proportion to the box's extents (at least
// one per axis; a flat axis gets one).
std::array<int, 3> cells_for(const Vec3& extent, double target) {
  const double longest = std::max({extent.x, extent.y, extent.z});
  std::array<int, 3> n{1, 1, 1};
  if (!(longest > 0)) return n;
  double volume = 1;  // of the box in units of the longest extent
  for (int k = 0; k < 3; ++k) volume *= std::max(extent[k] / longest, 1e-3);
  const double per_unit = std::cbrt(target / volume);
  for (int k = 0; k < 3; ++k)
    n[k] = std::clamp(static_cast<int>(std::ceil(per_unit * extent[k] / longest)), 1, 1 << 10);
  // Rounding up, and a flat axis's single cell, can multiply the count; member_grid_max_bytes
  // holds it to kMemberGridMaxCellsPerTarget times the target.
  while (double(n[0]) * n[1] * n[2] > kMemberGridMaxCellsPerTarget * target) {
    int& most = *std::max_element(n.begin(), n.end());
    most = std::max(1, most / 2);
  }
  return n;
}

}  // namespace

std::size_t member_grid_max_bytes(std::size_t objects) {
  if (objects == 0) return sizeof(MemberGrid);
  const double cells = kMemberGridMaxCellsPerTarget * kMemberGridCellsPerObject * double(objects);
  const double entries = double(member_grid_max_entries(objects));
  // The cells' offsets twice (the count being filled, and the grid's copy), the entries, the
  // objects' records, media and flags, and the bounds and quadrics they are built from.
  return sizeof(MemberGrid) +
         std::size_t(2 * (cells + 1) * sizeof(std::uint32_t) + entries * sizeof(std::int32_t)) +
         objects *
             (sizeof(GridObject) + sizeof(std::int32_t) + 1 + sizeof(Box) + sizeof(GridQuadric));
}

GridQuadric grid_quadric(const Tape& tape, int medium) {
  GridQuadric g;
  g.medium = medium;
  // evaluate() runs the one instruction, r[0] = quadrics[i](p), and returns r[0]: the same value.
  if (tape.code.size() == 1 && tape.code[0].op == Op::Quadric && tape.code[0].dst == 0) {
    g.quadric = tape.quadrics[tape.code[0].quadric];
    g.single = true;
  }
  return g;
}

MemberGrid build_member_grid(std::span<const Box> bounds, std::span<const GridQuadric> quadrics) {
  MemberGrid grid;
  grid.objects.resize(bounds.size());
  grid.medium.resize(bounds.size());
  grid.single.resize(bounds.size());
  for (std::size_t i = 0; i < bounds.size(); ++i) {
    grid.objects[i] = {bounds[i], quadrics[i].quadric};
    grid.medium[i] = quadrics[i].medium;
    grid.single[i] = quadrics[i].single;
  }
  for (const Box& b : bounds) grid.box = unite(grid.box, b);
  if (grid.box.empty()) return grid;
  double target = std::max(1.0, kMemberGridCellsPerObject * double(bounds.size()));
  const std::size_t max_entries = member_grid_max_entries(bounds.size());
  for (;;) {
    grid.cells = cells_for(grid.box.extent(), target);
    for (int k = 0; k < 3; ++k) {
      const double extent = grid.box.hi[k] - grid.box.lo[k];
      grid.inv_cell[k] = extent > 0 ? grid.cells[k] / extent : 0;
    }
    // Count each cell's objects, then fill: a counting sort keeps each list ascending.
    const std::size_t cells = std::size_t(grid.cells[0]) * grid.cells[1] * grid.cells[2];
    std::vector<std::uint32_t> count(cells + 1, 0);
    std::size_t entries = 0;
    auto for_cells = [&](const Box& b, auto&& f) {
      const int x0 = grid.cell(0, b.lo.x), x1 = grid.cell(0, b.hi.x);
      const int y0 = grid.cell(1, b.lo.y), y1 = grid.cell(1, b.hi.y);
      const int z0 = grid.cell(2, b.lo.z), z1 = grid.cell(2, b.hi.z);
      for (int z = z0; z <= z1; ++z)
        for (int y = y0; y <= y1; ++y)
          for (int x = x0; x <= x1; ++x)
            f((std::size_t(z) * grid.cells[1] + y) * grid.cells[0] + x);
    };
    for (const Box& b : bounds) {
      if (b.empty()) continue;
      for_cells(b, [&](std::size_t c) {
        ++count[c + 1];
        ++entries;
      });
      if (entries > max_entries) break;
    }
    if (entries > max_entries && cells > 1) {
      target = double(cells) / 8;  // too many entries: coarser
      continue;
    }
    for (std::size_t c = 0; c < cells; ++c) count[c + 1] += count[c];
    grid.begin = count;
    grid.members.resize(entries);
    for (std::size_t i = 0; i < bounds.size(); ++i) {
      if (bounds[i].empty()) continue;
      for_cells(bounds[i],
                [&](std::size_t c) { grid.members[count[c]++] = static_cast<std::int32_t>(i); });
    }
    return grid;
  }
}

}  // namespace nimbus
