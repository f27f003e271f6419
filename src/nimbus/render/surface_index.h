#pragma once
// What a ray can hit: the objects that have a surface and the sphere lights. `intersect` and
// `occluded` (render/scene.h) ask this index alone, so an acceleration structure over them
// replaces what is inside it and nothing else. Today it lists them, in scene order, and a query
// walks the list: the closest hit is the one of the lowest index among equal distances.

#include <cstddef>
#include <vector>

#include "nimbus/render/light.h"

namespace nimbus {

struct SceneObject;

struct SurfaceIndex {
  std::vector<int> objects;  // indices of the scene's objects with a surface
  std::vector<int> lights;   // indices of its lights with a surface (has_surface)
  // The sizes it was built for: render_into refuses a scene changed since (finish_scene).
  size_t object_count = 0, light_count = 0;
};

SurfaceIndex build_surface_index(const std::vector<SceneObject>& objects,
                                 const std::vector<Light>& lights);

}  // namespace nimbus
