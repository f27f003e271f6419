#pragma once
// Compiles a validated scene description into the flat run-time Scene: shapes to tapes with
// bounds, lights and surfaces to their run-time forms.

#include "nimbus/render/scene.h"
#include "nimbus/scene/scene_desc.h"

namespace nimbus {

// Throws SceneError (one line, with the JSON path) for what only compilation can see, such as an
// object whose shape is unbounded.
Scene compile_scene(const SceneDesc& desc);

// What a scene needs before it renders, derived from its objects, media, lights and settings:
// the list of index-matched medium objects, the scene's size, every colour's spectrum and the
// majorant octrees. compile_scene calls it; a scene built in code calls it once it is complete
// (and again after changing any of those). Throws std::invalid_argument for more than
// kMaxMediaAtPoint index-matched medium objects.
void finish_scene(Scene& scene);

}  // namespace nimbus
