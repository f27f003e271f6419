#pragma once
// What a ray can hit: the objects that have a surface and the sphere lights. `intersect` and
// `occluded` (render/scene.h) ask this index alone, through a bounding volume hierarchy over
// their boxes (binned SAH, render/surface_index.cpp), so that a ray's cost grows with the log of
// their number rather than with it (issue 26).
//
// The closest hit does not depend on the order in which the hierarchy visits them: each
// surface's own hit is computed over its box's part of the ray's whole range, never over a
// range cut short by an earlier hit, and among equal distances the surface listed first wins
// (objects in scene order, then lights), exactly as a walk down the list in that order.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "nimbus/math/box.h"
#include "nimbus/render/light.h"

namespace nimbus {

struct SceneObject;

// A node of the hierarchy: a box, and either two children (the first right after the node, the
// second at `index`) or `count` entries of the leaf order starting at `index`. A scene of a few
// surfaces has one node, a leaf: a list.
struct SurfaceNode {
  Box bounds;
  std::uint32_t index = 0;
  std::uint16_t count = 0;  // 0 for an inner node
  std::uint16_t axis = 0;   // an inner node's split axis: which child is nearer along a ray
};

struct SurfaceIndex {
  std::vector<int> objects;  // indices of the scene's objects with a surface, in scene order
  std::vector<int> lights;   // indices of its lights with a surface (has_surface), in order
  // The surfaces in leaf order, each as its position in the list objects-then-lights; those with
  // an empty box, which nothing hits, are left out.
  std::vector<std::uint32_t> entries;
  std::vector<SurfaceNode> nodes;  // nodes[0] is the root; empty when there is no surface
  // The sizes it was built for: render_into refuses a scene changed since (finish_scene).
  size_t object_count = 0, light_count = 0;
};

SurfaceIndex build_surface_index(const std::vector<SceneObject>& objects,
                                 const std::vector<Light>& lights);

}  // namespace nimbus
