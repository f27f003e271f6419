#pragma once
// Compiles a validated scene description into the flat run-time Scene: shapes to tapes with
// bounds, lights and surfaces to their run-time forms.

#include "nimbus/render/scene.h"
#include "nimbus/scene/scene_desc.h"

namespace nimbus {

// Throws SceneError (one line, with the JSON path) for what only compilation can see, such as an
// object whose shape is unbounded.
Scene compile_scene(const SceneDesc& desc);

}  // namespace nimbus
