#pragma once
// A hierarchy over the lights that have a position (point and sphere lights), for picking one
// of thousands in O(log N) (issue 26; after pbrt-v4's BVHLightSampler and Conty Estevez & Kulla
// 2018, without their orientation cones: nimbus's lights emit in every direction). Each node
// holds the box of its lights and their total power; at a point p a node's importance is its
// power over the squared distance from p to its box's centre, but no less than the box's own
// half-diagonal squared, so a light near p is not given a weight without bound. A pick descends
// from the root choosing a child in proportion to its importance; every light of positive power
// has a positive probability at every p, so next-event estimation through it stays unbiased.

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "nimbus/math/box.h"
#include "nimbus/render/light.h"

namespace nimbus {

struct LightTreeNode {
  Box bounds;
  double power = 0;  // Σ intensity (point) or radiance · π r² (sphere), in the largest channel
  // An inner node's second child (the first follows it), or a leaf's light (an index into the
  // scene's lights).
  std::uint32_t index = 0;
  bool leaf = false;
};

struct LightTree {
  std::vector<LightTreeNode> nodes;  // nodes[0] is the root; empty: no positioned light
  // Per scene light: the way from the root to its leaf, one bit per level (1: the second
  // child), and how many levels; depth -1 for a light outside the tree.
  std::vector<std::uint64_t> trail;
  std::vector<int> depth;
  std::vector<int> others;  // the lights outside the tree (at infinity, directional), in order
};

// Below this many positioned lights the exact per-light fluence choice (light_choice.h) is used:
// it costs a fluence per light per vertex but picks each light as well as can be.
inline constexpr int kLightTreeMinLights = 16;

// The tree over the point and sphere lights, or an empty one when there are fewer than
// kLightTreeMinLights of them.
LightTree build_light_tree(const std::vector<Light>& lights);

// How much a node may bring to p (see above); > 0 wherever its power is.
inline double light_node_importance(const LightTreeNode& node, const Vec3& p) {
  const Vec3 d = node.bounds.center() - p;
  const Vec3 half = node.bounds.extent() * 0.5;
  const double r2 = dot(half, half);
  const double d2 = dot(d, d);
  return node.power / (d2 > r2 ? d2 : r2 > 0 ? r2 : 1e-300);
}

// The probability of descending from inner node `at` to its first child at p.
inline double first_child_probability(const LightTree& tree, std::uint32_t at, const Vec3& p) {
  const double a = light_node_importance(tree.nodes[at + 1], p);
  const double b = light_node_importance(tree.nodes[tree.nodes[at].index], p);
  return a + b > 0 ? a / (a + b) : 0.5;
}

// A light of the tree picked at p from u in [0, 1), and the probability of the descent.
inline std::pair<int, double> descend_light_tree(const LightTree& tree, const Vec3& p, double u) {
  std::uint32_t at = 0;
  double pdf = 1;
  while (!tree.nodes[at].leaf) {
    const double p_first = first_child_probability(tree, at, p);
    if (u < p_first) {
      u /= p_first;
      pdf *= p_first;
      at = at + 1;
    } else {
      u = (u - p_first) / (1 - p_first);
      pdf *= 1 - p_first;
      at = tree.nodes[at].index;
    }
    u = std::min(u, 0x1.fffffffffffffp-1);  // rounding must not push it to 1
  }
  return {static_cast<int>(tree.nodes[at].index), pdf};
}

// The probability with which descend_light_tree picks `light` (an index into the scene's lights)
// at p: the product of the choices along its trail; 0 for a light outside the tree.
inline double light_tree_pdf(const LightTree& tree, int light, const Vec3& p) {
  const int depth = tree.depth[size_t(light)];
  if (depth < 0) return 0;
  const std::uint64_t trail = tree.trail[size_t(light)];
  std::uint32_t at = 0;
  double pdf = 1;
  for (int level = 0; level < depth; ++level) {
    const double p_first = first_child_probability(tree, at, p);
    if (trail >> level & 1) {
      pdf *= 1 - p_first;
      at = tree.nodes[at].index;
    } else {
      pdf *= p_first;
      at = at + 1;
    }
  }
  return pdf;
}

}  // namespace nimbus
