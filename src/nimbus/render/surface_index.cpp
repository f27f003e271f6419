#include "nimbus/render/surface_index.h"

#include <algorithm>
#include <array>
#include <numeric>

#include "nimbus/render/scene.h"

namespace nimbus {
namespace {

constexpr int kBins = 16;        // SAH candidates per axis (binned on the centroids)
constexpr int kMaxLeafSize = 4;  // entries a leaf may hold
// Up to this many surfaces the root is one leaf that a ray walks without a box test: a hierarchy
// over the five objects and a light of scenes/freeforms.json cost 4 % of its render time.
constexpr size_t kListSize = 8;
constexpr int kMedianDepth = 40;  // below this depth splits are by count, bounding the depth
constexpr double kCostVisit = 1;  // a node's box test, relative to one surface's test (SAH)

struct SurfaceItem {
  Box bounds;
  Vec3 centroid;
  std::uint32_t id;
};

double half_area(const Box& b) {
  if (b.empty()) return 0;
  const Vec3 e = b.extent();
  return e.x * e.y + e.y * e.z + e.z * e.x;
}

class SurfaceTreeBuilder {
 public:
  SurfaceTreeBuilder(std::vector<SurfaceItem>& items, SurfaceIndex& index)
      : items_(items), index_(index) {}

  // Builds the subtree of items [first, last) at node `at` (already pushed).
  void build(std::uint32_t at, size_t first, size_t last, int depth) {
    Box bounds, centroids;
    for (size_t i = first; i < last; ++i) {
      bounds = unite(bounds, items_[i].bounds);
      centroids = unite(centroids, Box{items_[i].centroid, items_[i].centroid});
    }
    index_.nodes[at].bounds = bounds;
    const size_t n = last - first;
    if (n <= size_t(kMaxLeafSize)) return make_leaf(at, first, last);
    size_t mid = 0;
    int axis = 0;
    if (depth >= kMedianDepth || !sah_split(bounds, centroids, first, last, axis, mid)) {
      // By count along the widest centroid axis: always splits, so the depth stays logarithmic.
      const Vec3 e = centroids.extent();
      axis = e.x >= e.y && e.x >= e.z ? 0 : e.y >= e.z ? 1 : 2;
      mid = first + n / 2;
      std::nth_element(items_.begin() + long(first), items_.begin() + long(mid),
                       items_.begin() + long(last),
                       [axis](const SurfaceItem& a, const SurfaceItem& b) {
                         return a.centroid[axis] < b.centroid[axis] ||
                                (a.centroid[axis] == b.centroid[axis] && a.id < b.id);
                       });
    }
    index_.nodes[at].axis = static_cast<std::uint16_t>(axis);
    const auto left = static_cast<std::uint32_t>(index_.nodes.size());
    index_.nodes.emplace_back();
    build(left, first, mid, depth + 1);
    const auto right = static_cast<std::uint32_t>(index_.nodes.size());
    index_.nodes.emplace_back();
    index_.nodes[at].index = right;
    build(right, mid, last, depth + 1);
  }

 private:
  void make_leaf(std::uint32_t at, size_t first, size_t last) {
    SurfaceNode& node = index_.nodes[at];
    node.index = static_cast<std::uint32_t>(index_.entries.size());
    node.count = static_cast<std::uint16_t>(last - first);
    for (size_t i = first; i < last; ++i) index_.entries.push_back(items_[i].id);
  }

  // The binned SAH split of [first, last) (Wald 2007), called above kMaxLeafSize items: false
  // when the centroids coincide on every axis; else partitions and sets axis and mid.
  bool sah_split(const Box& bounds, const Box& centroids, size_t first, size_t last, int& axis,
                 size_t& mid) {
    double best_cost = kInfinity;
    int best_axis = -1, best_bin = 0;
    for (int a = 0; a < 3; ++a) {
      const double lo = centroids.lo[a], width = centroids.hi[a] - lo;
      if (!(width > 0)) continue;
      std::array<Box, kBins> bin_bounds{};
      std::array<size_t, kBins> bin_count{};
      for (size_t i = first; i < last; ++i) {
        const int b = bin_of(items_[i].centroid[a], lo, width);
        bin_bounds[b] = unite(bin_bounds[b], items_[i].bounds);
        ++bin_count[b];
      }
      // Sweep from the right for the right sides' areas, then from the left.
      std::array<double, kBins> right_area{};
      std::array<size_t, kBins> right_count{};
      Box acc;
      size_t count = 0;
      for (int b = kBins - 1; b > 0; --b) {
        acc = unite(acc, bin_bounds[b]);
        count += bin_count[b];
        right_area[b] = half_area(acc);
        right_count[b] = count;
      }
      acc = Box{};
      count = 0;
      for (int b = 0; b < kBins - 1; ++b) {
        acc = unite(acc, bin_bounds[b]);
        count += bin_count[b];
        if (count == 0 || right_count[b + 1] == 0) continue;
        const double cost = kCostVisit + (half_area(acc) * double(count) +
                                          right_area[b + 1] * double(right_count[b + 1])) /
                                             half_area(bounds);
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = a;
          best_bin = b;
        }
      }
    }
    if (best_axis < 0) return false;
    const double lo = centroids.lo[best_axis], width = centroids.hi[best_axis] - lo;
    const auto split = std::partition(
        items_.begin() + long(first), items_.begin() + long(last), [&](const SurfaceItem& item) {
          return bin_of(item.centroid[best_axis], lo, width) <= best_bin;
        });
    axis = best_axis;
    mid = static_cast<size_t>(split - items_.begin());
    return mid > first && mid < last;
  }

  static int bin_of(double x, double lo, double width) {
    const int b = static_cast<int>(double(kBins) * ((x - lo) / width));
    return std::clamp(b, 0, kBins - 1);
  }

  static constexpr double kInfinity = Box::kInf;
  std::vector<SurfaceItem>& items_;
  SurfaceIndex& index_;
};

}  // namespace

SurfaceIndex build_surface_index(const std::vector<SceneObject>& objects,
                                 const std::vector<Light>& lights) {
  SurfaceIndex index;
  std::vector<SurfaceItem> items;
  for (size_t i = 0; i < objects.size(); ++i)
    if (objects[i].surface.type != Surface::Type::None) {
      index.objects.push_back(int(i));
      items.push_back({objects[i].bounds, objects[i].bounds.center(), 0});
    }
  for (size_t i = 0; i < lights.size(); ++i)
    if (has_surface(lights[i])) {
      index.lights.push_back(int(i));
      // Grown by a relative 1e-9: the analytic hit may round a hair outside the ball's box.
      Box b = surface_bounds(lights[i]);
      const double pad = 1e-9 * (lights[i].radius + length(lights[i].center));
      b.lo = b.lo - Vec3{pad, pad, pad};
      b.hi = b.hi + Vec3{pad, pad, pad};
      items.push_back({b, b.center(), 0});
    }
  for (size_t i = 0; i < items.size(); ++i) items[i].id = static_cast<std::uint32_t>(i);
  // A surface with an empty box can never be hit (e.g. a sphere below a double's resolution far
  // from the origin, built in code; compile_scene drops those): it has no entry, and no centroid
  // (an empty box's is NaN) to bin.
  std::erase_if(items, [](const SurfaceItem& item) { return item.bounds.empty(); });
  index.object_count = objects.size();
  index.light_count = lights.size();
  if (items.empty()) return index;
  index.entries.reserve(items.size());
  index.nodes.reserve(2 * items.size() / kMaxLeafSize + 1);
  index.nodes.emplace_back();
  if (items.size() <= kListSize) {
    index.nodes[0].count = static_cast<std::uint16_t>(items.size());
    for (const SurfaceItem& item : items) {
      index.nodes[0].bounds = unite(index.nodes[0].bounds, item.bounds);
      index.entries.push_back(item.id);
    }
    return index;
  }
  SurfaceTreeBuilder(items, index).build(0, 0, items.size(), 0);
  return index;
}

}  // namespace nimbus
