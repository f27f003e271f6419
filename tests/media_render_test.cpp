// The volumetric path tracer against analytic references (issue 4): transmittance through a
// field-density absorber, white furnaces, and Chandrasekhar's semi-infinite medium.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "nimbus/frep/bounds.h"
#include "nimbus/frep/primitives.h"
#include "nimbus/frep/tape.h"
#include "nimbus/math/constants.h"
#include "nimbus/media/medium_field.h"
#include "nimbus/render/renderer.h"
#include "support/chandrasekhar.h"
#include "support/stats.h"

namespace nimbus {
namespace {

Light environment(double radiance) {
  Light env;
  env.type = Light::Type::Environment;
  env.radiance = Rgb(radiance);
  return env;
}

SceneObject object_of(const ShapePtr& shape, Surface::Type surface, int medium, double ior = 1.5) {
  SceneObject obj;
  obj.tape = compile(*shape);
  obj.bounds = compute_bounds(obj.tape).box;
  obj.surface.type = surface;
  obj.surface.ior = ior;
  obj.medium = medium;
  return obj;
}

// Every reference at octree depth 0 (one global node), 4 and 12: the octree changes only the
// majorants, never the expected image.
class MediaRender : public ::testing::TestWithParam<int> {};

// Finishes a scene built in code as compile_scene would: field objects and majorant octrees.
void finish(Scene& scene, int octree_depth) {
  scene.settings.tracking.octree_depth = octree_depth;
  for (size_t i = 0; i < scene.objects.size(); ++i)
    if (scene.objects[i].surface.type == Surface::Type::None && scene.objects[i].medium >= 0)
      scene.field_objects.push_back(static_cast<int>(i));
  build_majorant_octrees(scene);
}

TEST_P(MediaRender, FieldAbsorberTransmittanceMatchesClosedForm) {
  const Rgb sigma_a({0.5, 1.0, 2.0});
  const int size = 20;
  Scene scene;
  scene.settings = {size, size, 256, 11, 100, {}};
  const double view = 2.2;
  scene.camera = orthographic_camera({0, 0, 4}, {0, 0, 0}, {0, 1, 0}, view, size, size);
  scene.lights.push_back(environment(1.0));
  Medium absorber;
  absorber.sigma_a = sigma_a;
  absorber.density = Medium::Density::Field;
  absorber.scale = 1.0;
  scene.media.push_back(absorber);
  scene.objects.push_back(
      object_of(make_shape(QuadricNode{sphere({0, 0, 0}, 1)}), Surface::Type::None, 0));
  finish(scene, GetParam());
  const RenderResult r = render(scene);

  // The reference averaged over each pixel's footprint: ∫ (1 − b² − s²) ds over the chord is
  // 4/3 (1 − b²)^{3/2}.
  auto T = [&](double b2, int c) {
    return b2 >= 1 ? 1.0 : std::exp(-sigma_a[c] * 4.0 / 3.0 * std::pow(1 - b2, 1.5));
  };
  double chi2 = 0;
  int dof = 0;
  const double px = view / size;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const int p = y * size + x;
      for (int c = 0; c < 3; ++c) {
        double ref = 0;
        const int k = 24;
        for (int i = 0; i < k; ++i)
          for (int j = 0; j < k; ++j) {
            const double sx = -view / 2 + (x + (i + 0.5) / k) * px;
            const double sy = view / 2 - (y + (j + 0.5) / k) * px;
            ref += T(sx * sx + sy * sy, c);
          }
        ref /= k * k;
        double var = r.film.variance_of_mean(p)[c];
        if (var <= 0) {
          // A pixel that no path can be absorbed in is exactly 1.
          if (std::abs(r.film.mean(p)[c] - ref) <= 1e-3) continue;
          // Otherwise every sample of a dark pixel-channel came out the same (all absorbed, by
          // chance): bound the variance by Bhatia–Davis for samples in [0, 3] (one channel of
          // three is tracked, weighted by 3) and count the pixel like the others.
          var = ref * (3 - ref) / scene.settings.spp;
        }
        const double z = (r.film.mean(p)[c] - ref) / std::sqrt(var);
        chi2 += z * z;
        ++dof;
      }
    }
  ASSERT_GT(dof, 300);
  // Per-pixel z-scores: their sum of squares is chi-square with dof degrees of freedom.
  EXPECT_LT(chi2, test::chi_square_critical(dof, 1e-4)) << "over " << dof << " pixel-channels";
  EXPECT_GT(r.counters.tracking.lookups, 0u);
}

// Albedo-1 media under a uniform environment of radiance 1 render 1 everywhere.
void expect_white_furnace(Scene& scene, int octree_depth) {
  scene.lights.push_back(environment(1.0));
  finish(scene, octree_depth);
  const RenderResult r = render(scene);
  const MeanEstimate m = image_mean(r.film);
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(m.standard_error[c], 0) << "the medium must make some noise";
    EXPECT_NEAR(m.mean[c], 1.0, 4 * m.standard_error[c]) << "channel " << c;
  }
  EXPECT_GT(r.counters.scatter_events, 1000u);
}

Scene furnace_scene(Medium medium, Surface::Type surface, const ShapePtr& shape) {
  Scene scene;
  scene.settings = {12, 12, 64, 5, 100000, {}};
  scene.camera = perspective_camera({0, 0.3, 3.5}, {0, 0, 0}, {0, 1, 0}, 40, 12, 12);
  medium.sigma_a = Rgb(0.0);
  scene.media.push_back(medium);
  scene.objects.push_back(object_of(shape, surface, 0));
  return scene;
}

Medium chromatic_scatterer() {
  Medium m;
  m.sigma_s = Rgb({1.0, 3.0, 6.0});
  m.g = 0.4;
  return m;
}

TEST_P(MediaRender, WhiteFurnaceConstantDensityIndexMatched) {
  Scene s = furnace_scene(chromatic_scatterer(), Surface::Type::None,
                          make_shape(QuadricNode{sphere({0, 0, 0}, 1)}));
  expect_white_furnace(s, GetParam());
}

TEST_P(MediaRender, WhiteFurnaceCloudDensityIndexMatched) {
  Medium cloud = chromatic_scatterer();
  cloud.density = Medium::Density::Cloud;
  cloud.sigma_s = Rgb({4.0, 8.0, 12.0});
  cloud.cloud = make_cloud_density(CloudParams{});
  Scene s =
      furnace_scene(cloud, Surface::Type::None, make_shape(QuadricNode{sphere({0, 0, 0}, 1)}));
  expect_white_furnace(s, GetParam());
}

TEST_P(MediaRender, WhiteFurnaceBehindLosslessDielectric) {
  Scene s = furnace_scene(chromatic_scatterer(), Surface::Type::Dielectric,
                          make_shape(QuadricNode{ellipsoid({0, 0, 0}, {1, 0.7, 0.9})}));
  expect_white_furnace(s, GetParam());
}

// A half-space of isotropic scatterers (a sphere of radius 1000 seen near its top), lit by a
// directional light and seen from above: Chandrasekhar's exact diffuse reflection.
void expect_chandrasekhar(double theta0_deg, double theta_deg, const Rgb& albedo,
                          int octree_depth) {
  const double R = 1000;
  const double mu0 = std::cos(theta0_deg * kPi / 180), mu = std::cos(theta_deg * kPi / 180);
  Scene scene;
  scene.settings = {6, 6, 2048, 3, 100000, {}};
  const Vec3 view_dir{std::sin(theta_deg * kPi / 180), -mu, 0};
  scene.camera =
      orthographic_camera(Vec3{0, 0, 0} - view_dir * 5.0, {0, 0, 0}, {0, 0, 1}, 0.5, 6, 6);
  Light sun;
  sun.type = Light::Type::Directional;
  sun.direction = normalize(Vec3{0, -mu0, -std::sqrt(1 - mu0 * mu0)});
  sun.irradiance = Rgb(2.0);
  scene.lights.push_back(sun);
  Medium m;
  m.sigma_s = albedo;
  m.sigma_a = Rgb(1.0) - albedo;  // mu_t = 1
  scene.media.push_back(m);
  scene.objects.push_back(
      object_of(make_shape(QuadricNode{sphere({0, -R, 0}, R)}), Surface::Type::None, 0));
  finish(scene, octree_depth);
  const RenderResult r = render(scene);
  const MeanEstimate est = image_mean(r.film);
  for (int c = 0; c < 3; ++c) {
    const double w = albedo[c];
    const double ref = test::half_space_reflected_radiance(2.0, w, mu0, mu);
    EXPECT_NEAR(est.mean[c], ref, 4 * est.standard_error[c])
        << "albedo " << w << ", theta0 " << theta0_deg << ", theta " << theta_deg;
  }
}

TEST_P(MediaRender, ChandrasekharHalfSpaceNormalIncidence) {
  expect_chandrasekhar(0, 30, Rgb({0.3, 0.7, 0.95}), GetParam());
}

TEST_P(MediaRender, ChandrasekharHalfSpaceGrazingIncidence) {
  expect_chandrasekhar(60, 0, Rgb({0.5, 0.9, 0.99}), GetParam());
}

INSTANTIATE_TEST_SUITE_P(OctreeDepth, MediaRender, ::testing::Values(0, 4, 12),
                         [](const ::testing::TestParamInfo<int>& info) {
                           return "depth" + std::to_string(info.param);
                         });

}  // namespace
}  // namespace nimbus
