#pragma once
// The scene's objects as triangle meshes (mesh/polygonize.h) for `nimbus view`'s page, which
// draws them with WebGL while the camera moves, at the display's rate and without the server.
// Each object is meshed to an error bound relative to its own size, but no finer than a fraction
// of the whole scene's (a power of two, so that it rarely changes): a scene of a thousand small
// objects stays a few hundred thousand triangles. Media's hulls, seen through, are four times
// coarser. An object whose function has not changed since
// the last scene keeps its mesh: an edited scene file re-meshes only what the edit touched.
//
// The page reads the meshes as one little-endian binary (encode_preview_meshes), every field four
// bytes so that the page views the arrays in place:
//   "NMSH", u32 format (1), u32 objects, f32 background r g b, f32 bounds lo xyz, hi xyz,
//   per object: f32 colour r g b, f32 opacity, u32 vertices, u32 triangles,
//               f32 positions[3 × vertices], f32 normals[3 × vertices], u32 indices[3 × triangles]
// Colours are linear RGB; opacity below 1 marks a medium's hull, drawn see-through.

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "nimbus/math/box.h"
#include "nimbus/mesh/mesh.h"
#include "nimbus/render/scene.h"

namespace nimbus {

// One object as the page draws it: a shape to mesh, or a mesh given (a sphere light's).
struct PreviewObject {
  Tape tape;  // in the scene's space
  std::shared_ptr<const TriangleMesh> mesh;
  Rgb colour{0.5};     // linear RGB
  double opacity = 1;  // < 1: a medium seen through its hull
};

// The scene's objects as the page draws them, and the colour behind them (the environment's).
struct PreviewScene {
  std::vector<PreviewObject> objects;
  Rgb background{0.0};
};

// What the page shows of each object: a surface's colour (a diffuse albedo, a metal's
// reflectance at normal incidence, an emitter's colour, a medium's single-scattering albedo
// through a dielectric), or a medium's translucent hull where there is no surface, as opaque as
// the medium is across half the object; and each sphere light as a sphere in its colour.
PreviewScene preview_scene(const Scene& scene);

struct PreviewMeshOptions {
  double relative_error = 1.0 / 256;  // ε as a fraction of each object's largest extent,
  double scene_error = 1.0 / 2048;    // and at least this fraction of the scene's (rounded)
  // Surface cells one object may take (memory and time); past it the object is meshed coarser.
  std::uint64_t max_cells = 1 << 18;
  // Triangles the page is sent at most, about: objects past it (in a scene of many thousand)
  // are not meshed, and are counted as skipped.
  std::uint64_t max_triangles = 4 << 20;
};

struct PreviewMeshStats {
  int meshed = 0, reused = 0, skipped = 0;  // skipped: empty, unbounded, too fine or past the
                                            // budget of triangles
  int given = 0;                            // sphere lights
  std::uint64_t triangles = 0;
};

// Meshes scenes one after the other, keeping the meshes of objects it has met before.
class PreviewMesher {
 public:
  explicit PreviewMesher(PreviewMeshOptions options = {}) : options_(options) {}
  // The scene's meshes, encoded for the page.
  std::string update(const PreviewScene& scene, PreviewMeshStats* stats = nullptr);

 private:
  PreviewMeshOptions options_;
  // By the object's function (tape_key) and error; only the last scene's are kept.
  std::map<std::string, std::shared_ptr<const TriangleMesh>> meshes_;
};

// The bytes that identify a tape's function: its quadrics and code, exactly.
std::string tape_key(const Tape& tape);

// The page's binary of these meshes (one per object, null for none).
std::string encode_preview_meshes(const PreviewScene& scene,
                                  const std::vector<std::shared_ptr<const TriangleMesh>>& meshes);

}  // namespace nimbus
