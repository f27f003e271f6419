#pragma once
// The compiled scene: flat, immutable, shared read-only by every thread.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "nimbus/frep/intersect.h"
#include "nimbus/frep/tape.h"
#include "nimbus/math/box.h"
#include "nimbus/math/mat4.h"
#include "nimbus/media/medium.h"
#include "nimbus/media/member_grid.h"
#include "nimbus/media/octree.h"
#include "nimbus/render/camera.h"
#include "nimbus/render/film.h"
#include "nimbus/render/light.h"
#include "nimbus/render/light_tree.h"
#include "nimbus/render/material.h"
#include "nimbus/render/surface_index.h"

namespace nimbus {

// How free paths and transmittance are estimated in media (docs/scene-format.md, integrator).
// The defaults are those of scene files and of scenes built in code alike (docs/scene-format.md;
// names in setting_names.h).
struct TrackingSettings {
  enum class Mode { Delta, SpectralMax, SpectralHistory, SpectralMis };
  enum class Absorption { Collide, Weight };
  enum class Transmittance { Ratio, ResidualRatio, RayMarching };
  enum class MajorantSource { Bound, Sample };
  Mode mode = Mode::SpectralMis;
  Absorption absorption = Absorption::Weight;
  bool decomposition = false;
  Transmittance transmittance = Transmittance::ResidualRatio;
  MajorantSource majorant_source = MajorantSource::Bound;
  int majorant_samples = 4096;  // points per octree leaf for source "sample"
  double majorant_scale = 1;  // multiplies every majorant; < 1 studies majorants that do not bound
  int octree_depth = 4;       // 0: one global node (the baseline)
};

// rgb: three fixed channels. spectral: `wavelengths` channels sampled per path (docs/spectra.md).
struct SpectralSettings {
  enum class Mode { Rgb, Spectral };
  Mode mode = Mode::Rgb;
  int wavelengths = 8;  // spectral mode: one of built_wavelength_counts() (wavelength_counts.h)
};

struct RenderSettings {
  // Where a pixel sample's numbers come from (render/path_sampler.h): Owen-scrambled Sobol' in
  // Morton order (math/zsobol.h), or independent PCG numbers, whose per-pixel sample variance
  // estimates the variance of the pixel's mean (tests that rely on it ask for it).
  enum class Sampler { ZSobol, Independent };
  // Next-event estimation at a vertex: a shadow ray to every light, or (the default) to one
  // light picked in proportion to its unoccluded fluence there, a constant sky left to BSDF and
  // phase sampling while another light shines (render/light_choice.h).
  enum class LightSampling { All, One };
  int width = 640, height = 480;
  int spp = 16;  // with a noise target, the most samples a pixel takes
  uint64_t seed = 0;
  int max_depth = 1000;
  TrackingSettings tracking;
  SpectralSettings spectral;
  Sampler sampler = Sampler::ZSobol;
  LightSampling light_sampling = LightSampling::One;
  // Manifold next-event estimation through smooth dielectric boundaries (render/manifold.h).
  bool manifold = true;
  // With it, also chains through a solid from outside (caustics) to sphere lights and emissive
  // surfaces, which BSDF sampling finds too; point and directional lights always have them.
  bool manifold_area_caustics = true;
  AovSet aovs = {};  // the layers written beside the colour (render/aov.h)
  // > 0: pixels take samples, in blocks, until their relative error is at most this
  // (render/noise_target.h); 0: every pixel takes spp.
  double noise_target = 0;
  int noise_min_spp = 16;  // the samples every block takes before its first decision
};

struct MicrofacetAlbedoLevels;

struct SceneObject {
  Tape tape;
  Box bounds;  // finite, conservative
  Surface surface;
  // A rough surface's albedo tables for its multiple-scattering lobe (render/microfacet_albedo.h);
  // null for others and where surface.multiple_scattering is off. Copies of an object share it.
  std::shared_ptr<const MicrofacetAlbedoLevels> albedo;
  int medium = -1;
  // The index of the description's object it comes from (one of its instances), or -1 for an
  // object built in code.
  int source = -1;
  // Its textures' frame: an index into Scene::texture_frames, or -1 where the object's own
  // coordinates are the scene's (texture_point).
  int texture_frame = -1;
};

// Whether an object holding `medium` (an index, or -1) with a surface of this type has a majorant
// octree of its own: a solid, whose medium a ray sees only inside it. Index-matched objects
// (surface none) share the field's.
inline bool has_own_octree(int medium, Surface::Type surface) {
  return medium >= 0 && surface != Surface::Type::None;
}

// The majorant octrees of the solid objects holding a medium, by object index: a slot per object
// (8 bytes; issue 26: an empty octree per object took 544), a tree per such solid.
struct SolidOctrees {
  std::vector<int> of_object;         // per object: its tree's index in `trees`, or -1
  std::vector<MajorantOctree> trees;  // in object order
  // The object's octree; an empty one for an object without.
  const MajorantOctree& at(size_t object) const {
    static const MajorantOctree none;
    const int k = object < of_object.size() ? of_object[object] : -1;
    return k >= 0 ? trees[size_t(k)] : none;
  }
};

struct Scene {
  Camera camera;
  RenderSettings settings;
  std::vector<SceneObject> objects;
  std::vector<Light> lights;
  std::vector<Medium> media;
  std::vector<int> field_objects;  // index-matched objects (surface none) holding a medium
  // Majorants and minorants (build_majorant_octrees): of the field, and inside each solid
  // object holding a medium (indexed by object; empty for the others).
  MemberGrid field_grid;  // which field objects may hold a point (index into field_objects)
  MajorantOctree field_octree;
  SolidOctrees solid_octrees;
  SurfaceIndex surfaces;  // what `intersect` and `occluded` search (finish_scene builds it)
  LightTree light_tree;   // for picking one of many lights (finish_scene builds it)
  std::vector<int> lights_at_infinity;  // what a ray that leaves the scene meets (finish_scene)
  bool dielectric_solids =
      false;  // whether an object has a smooth dielectric boundary (finish_scene)
  // The objects with emissive surfaces, which manifold sampling targets (render/emitter.h;
  // finish_scene).
  std::vector<int> emitters;
  // The objects whose media emit per unit length (render/glow.h; finish_scene).
  std::vector<int> glowing_objects;
  double scale = 1;  // size of the scene's bounds, for ray offsets
  // The exponent of its films (film.h: film_exponent of brightest_emission; finish_scene).
  int film_exponent = 0;
  // Scene-to-object maps of the textured objects placed by a transform (SceneObject).
  std::vector<Mat4> texture_frames;
  // What compile_scene left out and why, one line each (an object whose shape is empty): the
  // command line prints them as warnings, the Python module raises them as UserWarning.
  std::vector<std::string> warnings;
};

struct SurfaceHit {
  double t = 0;
  int object = -1;  // index into objects, or -1
  int light = -1;   // index of a sphere light, or -1
};

// Closest surface (objects with a surface, and sphere lights) along the ray in (0, t_max).
std::optional<SurfaceHit> intersect(const Scene& scene, const Ray& ray, double t_max);
// Whether any surface blocks the ray in (0, t_max); media do not block, nor does the light the
// shadow ray aims at (`target_light`, an index into lights, or -1), which would otherwise hide
// itself from a shadow ray whose origin was offset towards it.
bool occluded(const Scene& scene, const Ray& ray, double t_max, int target_light = -1);

// The largest emitted quantity in the scene, for the film's exponent: over its lights' emission
// (radiance, irradiance or intensity), emissive surfaces' radiance and media's emitted radiance
// (a temperature grid's at its hottest voxel), the largest value in any RGB channel or spectral
// bin; 0 for a scene that emits nothing. Call after complete_spectra.
double brightest_emission(const Scene& scene);

// The exponent of a film's depth sums (AovSums): film_exponent of the scene's size plus the
// camera's distance from the origin, the scale of the distances its camera rays meet things at.
int depth_exponent(const Scene& scene);

// A fresh film for the scene: its image's size, its film exponent and its layers (film_aovs).
Film make_film(const Scene& scene);
// The layers a film of these settings holds: the AOVs asked for, and Half for a noise target
// (render/noise_target.h).
AovSet film_aovs(const RenderSettings& settings);

// Gives every colour input of the scene its spectral curve (spectral_param.h), by role; spectral
// mode needs them, rgb mode ignores them. Call before build_majorant_octrees.
void complete_spectra(Scene& scene);

// The octree settings a scene's render settings ask for.
OctreeSettings octree_settings(const RenderSettings& settings);

// The octree of the media a ray sees from `inside`: -1 for the field of index-matched objects,
// else the index of a solid object holding a medium (only its medium, over its bounds).
MajorantOctree build_majorant_octree(const Scene& scene, int inside,
                                     const BuildMonitor& monitor = {});

// (Re)builds every octree of the scene: the field's, and one per solid object with a medium.
// Call after the objects, media and tracking settings are final. The monitor sees the fraction
// of all of them done; once cancelled, the scene must not be rendered.
void build_majorant_octrees(Scene& scene, const BuildMonitor& monitor = {});

// Where a texture of `object` is evaluated for the scene point x: in the object's own
// coordinates, those of its shape before the shape's top-level transform and its instance's
// placement, so that a texture moves with its object and every copy shows the same one.
inline Vec3 texture_point(const Scene& scene, const SceneObject& object, const Vec3& x) {
  return object.texture_frame < 0
             ? x
             : transform_point(scene.texture_frames[size_t(object.texture_frame)], x);
}

// The solid (dielectric) object containing p, the first in scene order if several do, or -1: a
// path that starts there (the camera may sit inside one) starts in its medium. Asks the
// SurfaceIndex, so its cost grows with the log of the number of objects.
int solid_containing(const Scene& scene, const Vec3& p);

// The outward unit normal of an object at a point on its surface (F decreases outwards).
Vec3 outward_normal(const SceneObject& object, const Vec3& p);

// A point just off the surface on the side that w points to, so the next ray starts clear of it.
// A shadow ray to a point stops short of it by the factor kShadowShrink, clear of the surface
// there.
inline constexpr double kShadowShrink = 1 - 1e-7;
Vec3 offset_origin(const Scene& scene, const Vec3& p, const Vec3& n, const Vec3& w);

}  // namespace nimbus
