#pragma once
// nimbus as a library (README, "Use nimbus as a library"): everything a program needs to load or
// build a scene, compile it, render it over any range of pixels and samples into a film, and
// write images or film files. Link the CMake target nimbus::core (find_package(nimbus)) or use
// pkg-config's nimbus.pc.
//
//   SceneDesc desc = load_scene_file("scene.json");       // or load_scene_json(json, name)
//   Scene scene = compile_scene(desc);                      // or build a Scene in code
//   RenderResult r = render(scene, options);                // or render_into(scene, film, options)
//   write_image("out.png", to_image(r.film));
//
// A render with checkpoints, resuming, progress and cancellation, as `nimbus render` runs it:
// RenderJob (job/render_job.h).

#include "nimbus/frep/bounds.h"
#include "nimbus/frep/primitives.h"
#include "nimbus/frep/tape.h"
#include "nimbus/io/film_file.h"
#include "nimbus/io/film_image.h"
#include "nimbus/io/output.h"
#include "nimbus/io/vdb_export.h"
#include "nimbus/job/render_job.h"
#include "nimbus/media/cloud_density.h"
#include "nimbus/media/constant_density.h"
#include "nimbus/media/field_density.h"
#include "nimbus/media/octree.h"
#include "nimbus/media/pattern_density.h"
#include "nimbus/media/temperature_emission.h"
#include "nimbus/media/vdb_density.h"
#include "nimbus/render/film.h"
#include "nimbus/render/renderer.h"
#include "nimbus/render/scene.h"
#include "nimbus/render/stats.h"
#include "nimbus/render/wavelength_counts.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
