// The path tracer against analytic answers: convex diffuse and lossless dielectric objects under
// a uniform environment, and determinism across thread counts.

#include <gtest/gtest.h>

#include <cmath>

#include "nimbus/frep/bounds.h"
#include "nimbus/frep/primitives.h"
#include "nimbus/frep/tape.h"
#include "nimbus/math/constants.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "support/stats.h"

namespace nimbus {
namespace render_test {

// The tests here take their tolerances from per-pixel sample variances, which estimate the
// variance of a pixel's mean for independent samples only: they ask for the independent sampler
// (the default sampler meets these references in sampler_render_test.cpp).
Scene sphere_scene(const Surface& surface, int size, int spp) {
  Scene scene;
  scene.settings = {size, size, spp, 7, 1000, {}, {}, RenderSettings::Sampler::Independent};
  scene.camera = orthographic_camera({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 2.5, size, size);
  SceneObject obj;
  obj.tape = compile(*make_shape(QuadricNode{sphere({0, 0, 0}, 1)}));
  obj.bounds = compute_bounds(obj.tape).box;
  obj.surface = surface;
  scene.objects.push_back(obj);
  Light env;
  env.type = Light::Type::Environment;
  env.emission = Rgb(1.0);
  scene.lights.push_back(env);
  finish_scene(scene);
  return scene;
}

// Pixels whose whole footprint lies inside (or outside) the unit disc seen orthographically.
std::vector<int> pixels_by_disc(const Scene& scene, bool inside) {
  std::vector<int> out;
  const int W = scene.settings.width, H = scene.settings.height;
  const double px = 2 * scene.camera.half_width / W;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const double sx = (2.0 * (x + 0.5) / W - 1) * scene.camera.half_width;
      const double sy = (1 - 2.0 * (y + 0.5) / H) * scene.camera.half_height;
      const double r = std::hypot(sx, sy);
      if (inside ? r < 1 - px : r > 1 + px) out.push_back(y * W + x);
    }
  return out;
}

void expect_region(const Film& film, const std::vector<int>& pixels, const Rgb& expected) {
  ASSERT_FALSE(pixels.empty());
  const MeanEstimate m = region_mean(film, pixels);
  for (int c = 0; c < 3; ++c) {
    const double tol = std::max(4 * m.standard_error[c], 1e-12);
    EXPECT_NEAR(m.mean[c], expected[c], tol) << "channel " << c << ", SE " << m.standard_error[c];
  }
}

TEST(Render, ConvexDiffuseObjectRendersItsAlbedoUnderUniformLight) {
  Surface diffuse;
  diffuse.type = Surface::Type::Diffuse;
  diffuse.albedo = Rgb({0.8, 0.5, 0.2});
  const Scene scene = sphere_scene(diffuse, 24, 64);
  const RenderResult r = render(scene);
  expect_region(r.film, pixels_by_disc(scene, true), diffuse.albedo.rgb);
  expect_region(r.film, pixels_by_disc(scene, false), Rgb(1.0));
  // Per pixel too: every inside pixel is within 5 standard errors of the albedo.
  for (int p : pixels_by_disc(scene, true))
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(r.film.mean(p)[c], diffuse.albedo.rgb[c],
                  5 * std::sqrt(r.film.variance_of_mean(p)[c]) + 1e-12);
}

TEST(Render, LosslessDielectricSphereRendersOne) {
  Surface glass;
  glass.type = Surface::Type::Dielectric;
  glass.ior = 1.5;
  const Scene scene = sphere_scene(glass, 24, 32);
  const RenderResult r = render(scene);
  expect_region(r.film, pixels_by_disc(scene, true), Rgb(1.0));
}

TEST(Render, ImageIsBitIdenticalForAnyThreadCount) {
  Surface diffuse;
  diffuse.type = Surface::Type::Diffuse;
  diffuse.albedo = Rgb(0.6);
  Scene scene = sphere_scene(diffuse, 33, 4);  // odd size: tiles of unequal shape
  Light sun;
  sun.type = Light::Type::Directional;
  sun.direction = normalize(Vec3{-1, -1, -1});
  sun.emission = Rgb(2.0);
  scene.lights.push_back(sun);
  finish_scene(scene);
  const RenderResult one = render(scene, RenderOptions{1, {}, {}, {}});
  const RenderResult two = render(scene, RenderOptions{2, {}, {}, {}});
  ASSERT_EQ(one.film.sum.size(), two.film.sum.size());
  for (size_t p = 0; p < one.film.sum.size(); ++p) {
    ASSERT_EQ(one.film.sum[p], two.film.sum[p]) << "pixel " << p;
    ASSERT_EQ(one.film.sum_sq[p], two.film.sum_sq[p]) << "pixel " << p;
  }
}

}  // namespace render_test
}  // namespace nimbus

namespace nimbus {
namespace render_test {

// A diffuse floor under a sphere light (radius r, radiance L_s): a uniform sphere above the
// horizon irradiates like a point of intensity π r² L_s at its centre, so the floor's radiance
// is albedo · L_s r² cos θ / d². With `more_lights`, a directional light (albedo E cos / π), a
// point light (albedo I cos / (π d²)) and an environment L_e join it; the sphere hides its own
// share of the sky from the floor: albedo L_e (1 − r² cos θ / d²). Both path tracers
// (next-event estimation with MIS against BSDF sampling, and spectral MIS's balance heuristic)
// must reproduce it, sampling every light at each vertex or one picked by its fluence.
void expect_lights_on_floor(TrackingSettings::Mode mode, bool more_lights,
                            RenderSettings::LightSampling light_sampling) {
  const int size = 16;
  const double r = 0.6, L_s = 5.0, albedo = 0.7;
  const Vec3 c{0.3, 2.0, -0.2};
  // Placed so that the sphere casts no shadow in view.
  const Vec3 sun_dir = normalize(Vec3{1, -1, 0}), point{-1.5, 1.0, 1.2};
  const double E_sun = 1.5, I_point = 0.8, L_env = 0.3;
  Scene scene;
  scene.settings = {size, size, 512, 9, 1000, {}, {}, RenderSettings::Sampler::Independent};
  scene.settings.tracking.mode = mode;
  scene.settings.light_sampling = light_sampling;
  // Looking down at the floor from the side, past the light; the view is 1 unit wide.
  scene.camera = orthographic_camera({3, 3, 3}, {0, 0, 0}, {0, 1, 0}, 1.0, size, size);
  SceneObject floor;
  floor.tape = compile(*box({-20, -1, -20}, {20, 0, 20}));
  floor.bounds = compute_bounds(floor.tape).box;
  floor.surface.type = Surface::Type::Diffuse;
  floor.surface.albedo = Rgb(albedo);
  scene.objects.push_back(floor);
  Light light;
  light.type = Light::Type::Sphere;
  light.center = c;
  light.radius = r;
  light.emission = Rgb(L_s);
  scene.lights.push_back(light);
  if (more_lights) {
    Light sun, bulb, sky;
    sun.type = Light::Type::Directional;
    sun.direction = sun_dir;
    sun.emission = Rgb(E_sun);
    bulb.type = Light::Type::Point;
    bulb.position = point;
    bulb.emission = Rgb(I_point);
    sky.type = Light::Type::Environment;
    sky.emission = Rgb(L_env);
    scene.lights.insert(scene.lights.end(), {sun, bulb, sky});
  }
  finish_scene(scene);
  const RenderResult res = render(scene);

  double chi2 = 0;
  int dof = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      // Average the closed form over the pixel's footprint on the floor (y = 0).
      double ref = 0;
      const int k = 8;
      for (int i = 0; i < k; ++i)
        for (int j = 0; j < k; ++j) {
          const Ray ray = scene.camera.generate(x + (i + 0.5) / k, y + (j + 0.5) / k);
          const Vec3 p = ray.at(-ray.o.y / ray.d.y);
          const Vec3 to_c = c - p;
          const double d2 = dot(to_c, to_c);
          const double sphere = r * r * (to_c.y / std::sqrt(d2)) / d2;
          ref += albedo * L_s * sphere;
          if (more_lights) {
            const Vec3 to_b = point - p;
            const double b2 = dot(to_b, to_b);
            ref += albedo * kInvPi * (E_sun * -sun_dir.y + I_point * (to_b.y / std::sqrt(b2)) / b2);
            ref += albedo * L_env * (1 - sphere);
          }
        }
      ref /= k * k;
      const int p = y * size + x;
      const double var = res.film.variance_of_mean(p)[0];
      ASSERT_GT(var, 0) << p;
      const double z = (res.film.mean(p)[0] - ref) / std::sqrt(var);
      chi2 += z * z;
      ++dof;
    }
  EXPECT_LT(chi2, test::chi_square_critical(dof, 1e-4)) << "over " << dof << " pixels";
}

constexpr auto kAll = RenderSettings::LightSampling::All;
constexpr auto kOne = RenderSettings::LightSampling::One;

TEST(Render, SphereLightOnDiffuseFloorMatchesClosedForm) {
  expect_lights_on_floor(TrackingSettings::Mode::Delta, false, kAll);
}

TEST(Render, SphereLightOnDiffuseFloorMatchesClosedFormWithSpectralMis) {
  expect_lights_on_floor(TrackingSettings::Mode::SpectralMis, false, kAll);
}

TEST(Render, FourLightsOnDiffuseFloorMatchClosedForm) {
  for (auto mode : {TrackingSettings::Mode::Delta, TrackingSettings::Mode::SpectralMis})
    for (auto light_sampling : {kAll, kOne}) {
      SCOPED_TRACE(testing::Message() << "mode " << int(mode) << ", one light per vertex "
                                      << (light_sampling == kOne));
      expect_lights_on_floor(mode, true, light_sampling);
    }
}

}  // namespace render_test
}  // namespace nimbus
