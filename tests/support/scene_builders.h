#pragma once
// Building small scenes in code for renderer tests, as compile_scene would from a file.

#include "nimbus/frep/bounds.h"
#include "nimbus/frep/tape.h"
#include "nimbus/media/octree.h"
#include "nimbus/render/scene.h"

namespace nimbus::test {

inline Light environment(double radiance) {
  Light env;
  env.type = Light::Type::Environment;
  env.emission = Rgb(radiance);
  return env;
}

inline SceneObject object_of(const ShapePtr& shape, Surface::Type surface, int medium,
                             double ior = 1.5) {
  SceneObject obj;
  obj.tape = compile(*shape);
  obj.bounds = compute_bounds(obj.tape).box;
  obj.surface.type = surface;
  obj.surface.ior = ior;
  obj.medium = medium;
  return obj;
}

// Tracking settings for a mode; shadow rays use residual ratio tracking with decomposition and
// ratio tracking without.
inline TrackingSettings tracking_settings(TrackingSettings::Mode mode,
                                          TrackingSettings::Absorption absorption,
                                          bool decomposition, int octree_depth) {
  TrackingSettings t;
  t.mode = mode;
  t.absorption = absorption;
  t.decomposition = decomposition;
  t.transmittance = decomposition ? TrackingSettings::Transmittance::ResidualRatio
                                  : TrackingSettings::Transmittance::Ratio;
  t.octree_depth = octree_depth;
  return t;
}

// Field objects, spectra and majorant octrees, as compile_scene derives them.
inline void finish_media(Scene& scene) {
  for (size_t i = 0; i < scene.objects.size(); ++i)
    if (scene.objects[i].surface.type == Surface::Type::None && scene.objects[i].medium >= 0)
      scene.field_objects.push_back(static_cast<int>(i));
  complete_spectra(scene);
  build_majorant_octrees(scene);
}

}  // namespace nimbus::test
