#pragma once
// Compiles a validated scene description into the flat run-time Scene: shapes to tapes with
// bounds, lights and surfaces to their run-time forms.

#include "nimbus/render/scene.h"
#include "nimbus/scene/scene_desc.h"

namespace nimbus {

// The largest optical thickness (an upper bound of sigma_t · density across an object's bounds)
// that a scene file may give a medium. Tracking takes about that many steps along a ray, so a
// larger one would look like a hang; realistic media stay far below (a 1 km cloud at 100 /m:
// 10^5; skin at 40 /mm over 10 cm: 4 · 10^3).
inline constexpr double kMaxOpticalThickness = 1e6;

// Throws SceneError (one line, with the JSON path) for what only compilation can see, such as an
// object whose shape is unbounded or a medium above kMaxOpticalThickness.
// The monitor watches the majorant octrees' build, the part that can take seconds
// (media/octree.h); a cancelled compile returns a scene that must not be rendered.
Scene compile_scene(const SceneDesc& desc, const BuildMonitor& monitor = {});

// What a scene needs before it renders, derived from its objects, media, lights and settings:
// the list of index-matched medium objects, the scene's size, every colour's spectrum and the
// majorant octrees. compile_scene calls it; a scene built in code calls it once it is complete
// (and again after changing any of those). Throws std::invalid_argument for more than
// kMaxMediaAtPoint index-matched medium objects.
void finish_scene(Scene& scene, const BuildMonitor& monitor = {});

}  // namespace nimbus
