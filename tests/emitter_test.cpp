// Points on emissive surfaces for the walk (render/emitter.h): the density that sampling reports
// is the one it samples with, shown by the mean of 1 / pdf_A, which is the surface's area, and
// the density re-evaluated at each sampled point is the one reported.

#include "nimbus/render/emitter.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "nimbus/math/constants.h"
#include "nimbus/math/rng.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "support/film_blocks.h"

namespace nimbus {
namespace {

Scene emitter_scene(const std::string& shape) {
  return compile_scene(load_scene_text(fmt::format(R"({{"film": {{"width": 8, "height": 8}},
      "camera": {{"from": [0, 0, 5], "to": [0, 0, 0]}},
      "shapes": {{"lamp": {}}},
      "objects": [{{"shape": "lamp", "surface": {{"type": "emissive", "radiance": 1}}}}]}})",
                                                   shape),
                                       "emitter_test"));
}

// The mean of 1 / pdf_A over samples estimates the area of the surface the sampler covers; it
// must match `area` within 4 standard errors, and every sample's density must be reproduced.
void expect_area(const std::string& shape, double area, const char* what) {
  const Scene scene = emitter_scene(shape);
  ASSERT_EQ(scene.emitters.size(), 1u) << what;
  Rng rng(17);
  const int n = 40000;
  double sum = 0, sum2 = 0;
  for (int s = 0; s < n; ++s) {
    const double u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
    const auto e = sample_emitter_point(scene, scene.emitters[0], u1, u2, u3);
    double w = 0;
    if (e) {
      w = 1 / e->pdf_area;
      EXPECT_NEAR(emitter_point_pdf(scene, scene.emitters[0], e->y, e->n), e->pdf_area,
                  1e-6 * e->pdf_area)
          << what;
    }
    sum += w;
    sum2 += w * w;
  }
  const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / (n - 1));
  EXPECT_NEAR(mean, area, 4 * se) << what << ", SE " << se;
  EXPECT_LT(se, 0.05 * area) << what;  // the test can tell a wrong density from a right one
}

TEST(EmitterSampling, SphereAboutItsCentreIsUniform) {
  const Scene scene = emitter_scene(R"({"type": "sphere", "center": [0.2, 0, 0], "radius": 0.5})");
  const auto e = sample_emitter_point(scene, 0, 0.3, 0.7, 0.5);
  ASSERT_TRUE(e);
  EXPECT_NEAR(e->pdf_area, 1 / (4 * kPi * 0.25), 1e-9);
  expect_area(R"({"type": "sphere", "center": [0.2, 0, 0], "radius": 0.5})", 4 * kPi * 0.25,
              "sphere");
}

TEST(EmitterSampling, BoxFacesAtEveryAngle) {
  expect_area(R"({"type": "box", "min": [-0.5, -0.2, -0.3], "max": [0.5, 0.2, 0.3]})",
              2 * (1.0 * 0.4 + 0.4 * 0.6 + 1.0 * 0.6), "box");
}

// From the centre between two balls, a ray meets both of a ball's roots or none.
TEST(EmitterSampling, TwoBallsWithTwoRootsPerRay) {
  expect_area(R"({"type": "union", "shapes": [
      {"type": "sphere", "center": [-0.6, 0, 0], "radius": 0.3},
      {"type": "sphere", "center": [0.6, 0, 0], "radius": 0.3}]})",
              2 * 4 * kPi * 0.09, "two balls");
}

// An emissive ball lights a floor as a sphere light of the same radiance does: next-event
// estimation to the surface's sampled points, weighted by MIS against BSDF sampling, gives the
// image that the sphere light's cone sampling gives (within 4 standard errors per 8 x 8 block),
// in rgb and spectral modes.
TEST(EmitterSampling, EmissiveBallLightsLikeASphereLight) {
  const auto text = [](bool surface, const char* spectrum) {
    return fmt::format(
        R"({{"film": {{"width": 16, "height": 16}},
        "camera": {{"from": [0, 2.5, 3], "to": [0, 0, 0], "fov": 45}},
        "integrator": {{"spp": 64, "seed": 4, "sampler": "independent"}},
        "spectrum": {{"mode": "{}"}},
        "lights": [{}],
        "shapes": {{"floor": {{"type": "box", "min": [-4, -1, -4], "max": [4, 0, 4]}},
                   "lamp": {{"type": "sphere", "center": [0.5, 1.0, -0.5], "radius": 0.4}}}},
        "objects": [{{"shape": "floor", "surface": {{"type": "diffuse", "albedo": 0.6}}}}{}]}})",
        spectrum,
        surface
            ? ""
            : R"({"type": "sphere", "center": [0.5, 1.0, -0.5], "radius": 0.4, "radiance": [4, 3, 2]})",
        surface ? R"(, {"shape": "lamp", "surface": {"type": "emissive", "radiance": [4, 3, 2]}})"
                : "");
  };
  for (const char* spectrum : {"rgb", "spectral"}) {
    RenderOptions options;
    options.threads = 2;
    const RenderResult a =
        render(compile_scene(load_scene_text(text(true, spectrum), "a")), options);
    const RenderResult b =
        render(compile_scene(load_scene_text(text(false, spectrum), "b")), options);
    test::expect_blocks_agree(a.film, b.film, 16, spectrum);
  }
}

}  // namespace
}  // namespace nimbus
