#include "nimbus/render/memory_estimate.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "nimbus/math/vec3.h"
#include "nimbus/media/member_grid.h"
#include "nimbus/media/octree.h"
#include "nimbus/render/film.h"

namespace nimbus {

MemoryEstimate estimate_render_memory(int width, int height, std::size_t octrees, int bins,
                                      int threads, std::size_t field_objects, AovSet aovs) {
  const double pixels = double(width) * double(height);
  MemoryEstimate e;
  e.film =
      pixels * double(sizeof(ExactRgb) + sizeof(Rgb) + sizeof(uint32_t) + aov_film_bytes(aovs));
  // The float image, and as much again for a writer's rows (EXR slices, PNG bytes).
  e.image = 2 * pixels * double(3 + aov_image_floats(aovs)) * sizeof(float);
  // At the node budget, while building: the node, its bounds, its centre, level and list of
  // members (one, in a solid), and the pruned copy.
  const double per_node = sizeof(OctreeNode) + 2.0 * bins * sizeof(double) + sizeof(Vec3) + 4 +
                          sizeof(std::vector<std::int32_t>) + sizeof(std::int32_t);
  e.octrees = double(octrees) * double(kOctreeMaxNodes) * per_node * 2;
  if (field_objects > 0) {
    // The field octree's lists at their cap, and the leaves' copy.
    const double entries = double(octree_max_list_entries(field_objects));
    e.media_lists =
        2 * entries * sizeof(std::int32_t) + double(member_grid_max_bytes(field_objects));
  }
  e.threads = double(threads) * (1 << 20);
  return e;
}

double object_memory(std::size_t copies, std::size_t quadrics) {
  return double(copies) * (1400.0 + 320.0 * double(quadrics));
}

std::uint64_t available_memory() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  std::uint64_t kib = 0;
  std::string unit;
  while (meminfo >> key >> kib >> unit)
    if (key == "MemAvailable:") return kib * 1024;
  return 0;
}

std::uint64_t parse_memory_size(const std::string& text) {
  // Decimal digits with an optional fraction (std::stod alone also took "0x10" as 16 bytes, and
  // "inf" or "1e3").
  size_t used = 0;
  while (used < text.size() &&
         (std::isdigit(static_cast<unsigned char>(text[used])) || (text[used] == '.' && used > 0)))
    ++used;
  double value = 0;
  try {
    if (used > 0) value = std::stod(text.substr(0, used));
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || !(value > 0) || !std::isfinite(value))
    throw std::invalid_argument(
        fmt::format("\"{}\" is not a size (a positive number with K, M, G or T)", text));
  const std::string suffix = text.substr(used);
  double scale = 1;
  if (suffix == "K" || suffix == "k")
    scale = 1024.0;
  else if (suffix == "M" || suffix == "m")
    scale = 1024.0 * 1024;
  else if (suffix == "G" || suffix == "g")
    scale = 1024.0 * 1024 * 1024;
  else if (suffix == "T" || suffix == "t")
    scale = 1024.0 * 1024 * 1024 * 1024;
  else if (!suffix.empty())
    throw std::invalid_argument(
        fmt::format("\"{}\": unknown size suffix \"{}\" (K, M, G or T)", text, suffix));
  return static_cast<std::uint64_t>(value * scale);
}

std::string format_memory(double bytes) {
  if (bytes >= 1024.0 * 1024 * 1024)
    return fmt::format("{:.1f} GiB", bytes / (1024.0 * 1024 * 1024));
  return fmt::format("{:.1f} MiB", bytes / (1024.0 * 1024));
}

}  // namespace nimbus
