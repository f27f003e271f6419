#pragma once
// Compiles a validated scene description into the flat run-time Scene: shapes to tapes with
// bounds, lights and surfaces to their run-time forms.

#include <vector>

#include "nimbus/render/scene.h"
#include "nimbus/scene/input_file.h"
#include "nimbus/scene/scene_desc.h"

namespace nimbus {

// The largest number of null collisions along a ray across an object (an upper bound from its
// majorant octree: null rate times the object's size) that a scene file may give a medium whose
// optical thickness is above it. Tracking takes about that many steps along a ray, so more would
// look like a hang; realistic media stay far below (a 1 km cloud at 100 /m: 10^5; skin at 40 /mm
// over 10 cm: 4 · 10^3). A medium optically thicker but homogeneous and gray costs its real
// collisions only: the walk is clipped to the object's surface, its octree node has no null rate.
inline constexpr double kMaxOpticalThickness = 1e6;

// Throws SceneError (one line, with the JSON path) for what only compilation can see, such as an
// object whose shape is unbounded or a medium that may cost more than kMaxOpticalThickness null
// collisions per ray. An object with instances becomes one object per instance, in their order.
// The monitor watches the objects' compile (objects) and the majorant octrees' build (progress,
// media/octree.h); its cancel stops both: a cancelled compile returns a scene that must not be
// rendered. `inputs` gets the files the description read (instances files) and those compiling
// it reads (VDB grids), in that order: what a render's fingerprint holds and its outputs must not
// overwrite.
Scene compile_scene(const SceneDesc& desc, const BuildMonitor& monitor = {},
                    std::vector<InputFile>* inputs = nullptr);

// The run-time camera of a description's camera for the film's size.
Camera compile_camera(const CameraDesc& camera, const RenderSettings& film);
// The medium an object of the description holds once compiled: its own, or -1 where an opaque
// surface (diffuse, emissive) hides it; only solids and index-matched objects hold one.
int compiled_medium(const ObjectDesc& object);

// What a scene needs before it renders, derived from its objects, media, lights and settings:
// the list of index-matched medium objects, the scene's size, every colour's spectrum and the
// majorant octrees. compile_scene calls it; a scene built in code calls it once it is complete
// (and again after changing any of those). Throws std::invalid_argument when the index-matched
// media have more than kMaxPhaseLobes different phase anisotropies (medium_field.h).
void finish_scene(Scene& scene, const BuildMonitor& monitor = {});

}  // namespace nimbus
