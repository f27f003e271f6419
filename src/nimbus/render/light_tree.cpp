#include "nimbus/render/light_tree.h"

#include <algorithm>
#include <cmath>

#include "nimbus/math/constants.h"

namespace nimbus {
namespace {

// The light's power in its largest channel (RGB or a spectral bin): the tree's weights are the
// same for every path, whatever its wavelengths.
double light_power(const Light& light) {
  const double e = std::max(largest_value(light.emission), 0.0);
  return light.type == Light::Type::Point ? e : e * kPi * light.radius * light.radius;
}

bool positioned(const Light& light) {
  return light.type == Light::Type::Point || light.type == Light::Type::Sphere;
}

struct LightItem {
  Box bounds;
  Vec3 centre;
  double power;
  int light;
};

class LightTreeBuilder {
 public:
  LightTreeBuilder(std::vector<LightItem>& items, LightTree& tree) : items_(items), tree_(tree) {}

  // The subtree of items [first, last) at node `at`, reached from the root by `trail`.
  void build(std::uint32_t at, size_t first, size_t last, std::uint64_t trail, int depth) {
    LightTreeNode& node = tree_.nodes[at];
    for (size_t i = first; i < last; ++i) {
      node.bounds = unite(node.bounds, items_[i].bounds);
      node.power += items_[i].power;
    }
    if (last - first == 1) {
      node.leaf = true;
      node.index = static_cast<std::uint32_t>(items_[first].light);
      tree_.trail[size_t(items_[first].light)] = trail;
      tree_.depth[size_t(items_[first].light)] = depth;
      return;
    }
    // Halves by count along the widest spread of the centres: depth ⌈log2 N⌉ (< 64 bits).
    Box centres;
    for (size_t i = first; i < last; ++i)
      centres = unite(centres, Box{items_[i].centre, items_[i].centre});
    const Vec3 e = centres.extent();
    const int axis = e.x >= e.y && e.x >= e.z ? 0 : e.y >= e.z ? 1 : 2;
    const size_t mid = first + (last - first) / 2;
    std::nth_element(items_.begin() + long(first), items_.begin() + long(mid),
                     items_.begin() + long(last), [axis](const LightItem& a, const LightItem& b) {
                       return a.centre[axis] < b.centre[axis] ||
                              (a.centre[axis] == b.centre[axis] && a.light < b.light);
                     });
    const auto left = static_cast<std::uint32_t>(tree_.nodes.size());
    tree_.nodes.emplace_back();
    build(left, first, mid, trail, depth + 1);
    const auto right = static_cast<std::uint32_t>(tree_.nodes.size());
    tree_.nodes.emplace_back();
    tree_.nodes[at].index = right;
    build(right, mid, last, trail | (std::uint64_t{1} << depth), depth + 1);
  }

 private:
  std::vector<LightItem>& items_;
  LightTree& tree_;
};

}  // namespace

LightTree build_light_tree(const std::vector<Light>& lights) {
  LightTree tree;
  std::vector<LightItem> items;
  for (size_t i = 0; i < lights.size(); ++i) {
    const Light& l = lights[i];
    if (!positioned(l)) continue;
    const Vec3 c = l.type == Light::Type::Point ? l.position : l.center;
    const double r = l.type == Light::Type::Sphere ? l.radius : 0.0;
    items.push_back({Box{c - Vec3{r, r, r}, c + Vec3{r, r, r}}, c, light_power(l), int(i)});
  }
  if (items.size() < size_t(kLightTreeMinLights)) return tree;
  for (size_t i = 0; i < lights.size(); ++i)
    if (!positioned(lights[i])) tree.others.push_back(int(i));
  tree.trail.assign(lights.size(), 0);
  tree.depth.assign(lights.size(), -1);
  tree.nodes.reserve(2 * items.size());
  tree.nodes.emplace_back();
  LightTreeBuilder(items, tree).build(0, 0, items.size(), 0, 0);
  return tree;
}

}  // namespace nimbus
