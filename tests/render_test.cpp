// The path tracer against analytic answers: convex diffuse and lossless dielectric objects under
// a uniform environment, and determinism across thread counts.

#include <gtest/gtest.h>

#include <cmath>

#include "nimbus/frep/bounds.h"
#include "nimbus/frep/primitives.h"
#include "nimbus/frep/tape.h"
#include "nimbus/render/renderer.h"

namespace nimbus {
namespace {

Scene sphere_scene(const Surface& surface, int size, int spp) {
  Scene scene;
  scene.settings = {size, size, spp, 7, 1000, {}};
  scene.camera = orthographic_camera({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 2.5, size, size);
  SceneObject obj;
  obj.tape = compile(*make_shape(QuadricNode{sphere({0, 0, 0}, 1)}));
  obj.bounds = compute_bounds(obj.tape).box;
  obj.surface = surface;
  scene.objects.push_back(obj);
  Light env;
  env.type = Light::Type::Environment;
  env.radiance = Rgb(1.0);
  scene.lights.push_back(env);
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
  expect_region(r.film, pixels_by_disc(scene, true), diffuse.albedo);
  expect_region(r.film, pixels_by_disc(scene, false), Rgb(1.0));
  // Per pixel too: every inside pixel is within 5 standard errors of the albedo.
  for (int p : pixels_by_disc(scene, true))
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(r.film.mean(p)[c], diffuse.albedo[c],
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
  sun.irradiance = Rgb(2.0);
  scene.lights.push_back(sun);
  const RenderResult one = render(scene, {1, {}});
  const RenderResult two = render(scene, {2, {}});
  ASSERT_EQ(one.film.sum.size(), two.film.sum.size());
  for (size_t p = 0; p < one.film.sum.size(); ++p) {
    ASSERT_EQ(one.film.sum[p], two.film.sum[p]) << "pixel " << p;
    ASSERT_EQ(one.film.sum_sq[p], two.film.sum_sq[p]) << "pixel " << p;
  }
}

}  // namespace
}  // namespace nimbus
