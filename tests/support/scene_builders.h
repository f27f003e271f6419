#pragma once
// Building small scenes in code for renderer tests, as compile_scene would from a file.

#include <cmath>

#include "nimbus/frep/bounds.h"
#include "nimbus/frep/primitives.h"
#include "nimbus/frep/tape.h"
#include "nimbus/math/constants.h"
#include "nimbus/media/octree.h"
#include "nimbus/render/scene.h"
#include "nimbus/scene/compile.h"

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

// Issue 17's scene without its objects: an 8 × 8 orthographic view of the unit sphere's region
// at 1 024 spp, lit by a sphere light inside the sphere, with media[0] a medium of `density`
// (chromatic scattering, grey absorption, g 0.3). The caller adds the objects holding it.
inline Scene bulb_in_medium(double density, TrackingSettings::Mode mode) {
  Scene scene;
  scene.settings = {8,    8,
                    1024, 31,
                    1000, tracking_settings(mode, TrackingSettings::Absorption::Collide, false, 4),
                    {},   RenderSettings::Sampler::Independent};
  scene.camera = orthographic_camera({0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 2.1, 8, 8);
  Medium m;
  m.sigma_s = Rgb({1.0, 2.0, 3.0}) * density;
  m.sigma_a = Rgb(1.0) * density;
  m.g = 0.3;
  scene.media.push_back(m);
  Light bulb;
  bulb.type = Light::Type::Sphere;
  bulb.center = {0.2, 0.1, -0.1};
  bulb.radius = 0.45;
  bulb.emission = Rgb(3.0);
  scene.lights.push_back(bulb);
  return scene;
}

// Field objects, spectra and majorant octrees, as compile_scene derives them.
inline void finish_media(Scene& scene) {
  finish_scene(scene);
}

// Chandrasekhar's half-space: `medium` filling a sphere of radius 1000 seen near its top by a
// 6×6 orthographic camera at zenith angle theta, lit by a sun of `irradiance` at zenith angle
// theta0 (chandrasekhar.h gives the reflected radiance).
inline Scene half_space_scene(double theta0_deg, double theta_deg, const Medium& medium,
                              const SpectralParam& irradiance, const RenderSettings& settings) {
  const double R = 1000;
  const double mu0 = std::cos(theta0_deg * kPi / 180), mu = std::cos(theta_deg * kPi / 180);
  Scene scene;
  scene.settings = settings;
  const Vec3 view_dir{std::sin(theta_deg * kPi / 180), -mu, 0};
  scene.camera = orthographic_camera(Vec3{0, 0, 0} - view_dir * 5.0, {0, 0, 0}, {0, 0, 1}, 0.5,
                                     settings.width, settings.height);
  Light sun;
  sun.type = Light::Type::Directional;
  sun.direction = normalize(Vec3{0, -mu0, -std::sqrt(1 - mu0 * mu0)});
  sun.emission = irradiance;
  scene.lights.push_back(sun);
  scene.media.push_back(medium);
  scene.objects.push_back(
      object_of(make_shape(QuadricNode{sphere({0, -R, 0}, R)}), Surface::Type::None, 0));
  finish_media(scene);
  return scene;
}

}  // namespace nimbus::test
