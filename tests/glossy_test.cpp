// Rough boundaries in the path loop (render/glossy.h): a rough conductor under a uniform sky
// reflects its directional albedo, computed by quadrature of the BSDF; a nearly smooth rough
// dielectric gives the smooth one's image; light reaches a translucent object through a rough
// boundary from a point light as from a small sphere light of the same intensity.

#include "nimbus/render/glossy.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>

#include "nimbus/math/constants.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "support/film_blocks.h"
#include "support/stats.h"

namespace nimbus {
namespace {

RenderResult render_text(const std::string& text, int threads = 2) {
  RenderOptions options;
  options.threads = threads;
  return render(compile_scene(load_scene_text(text, "glossy_test")), options);
}

// ∫ f(wo, wi) F cos θi dωi over the hemisphere, by Simpson's rule in θ and φ: the directional
// albedo of a rough conductor of index eta + ik seen at θo from its normal.
double conductor_albedo(double alpha, double eta, double k, double theta_o) {
  const Vec3 wo{std::sin(theta_o), 0, std::cos(theta_o)};
  return test::simpson(
      [&](double theta) {
        return std::sin(theta) * std::cos(theta) *
               test::simpson(
                   [&](double phi) {
                     const Vec3 wi{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                   std::cos(theta)};
                     const double f = conductor_microfacet(alpha, wo, wi);
                     if (!(f > 0)) return 0.0;
                     return f * fresnel_conductor(std::abs(dot(wo, reflection_half_vector(wo, wi))),
                                                  eta, k);
                   },
                   0, 2 * kPi, 512);
      },
      0, kPi / 2, 256);
}

// A flat rough gold-coloured conductor seen at 45° through an orthographic camera under a sky of
// radiance 1: every pixel is the albedo at 45°, with the sky sampled by BSDF sampling alone
// (light_sampling "one" leaves a constant sky to it) and by both techniques under MIS ("all").
TEST(GlossyRender, RoughConductorUnderAUniformSkyReflectsItsAlbedo) {
  const std::array<double, 3> eta{0.18, 0.42, 1.37}, k{3.42, 2.35, 1.77};
  for (const double alpha : {0.1, 0.5}) {
    for (const char* light_sampling : {"one", "all"}) {
      const std::string text = fmt::format(
          R"({{"film": {{"width": 8, "height": 8}},
  "camera": {{"type": "orthographic", "from": [0, 2, 2], "to": [0, 0, 0], "width": 0.5}},
  "integrator": {{"spp": 256, "seed": 5, "sampler": "independent",
                  "light_sampling": "{}"}},
  "lights": [{{"type": "environment", "radiance": 1}}],
  "shapes": {{"slab": {{"type": "box", "min": [-20, -1, -20], "max": [20, 0, 20]}}}},
  "objects": [{{"shape": "slab", "surface": {{"type": "conductor", "roughness": {},
      "eta": [{}, {}, {}], "k": [{}, {}, {}]}}}}]}})",
          light_sampling, alpha, eta[0], eta[1], eta[2], k[0], k[1], k[2]);
      const RenderResult r = render_text(text);
      std::vector<int> all(64);
      for (int p = 0; p < 64; ++p) all[size_t(p)] = p;
      const MeanEstimate m = region_mean(r.film, all);
      for (int c = 0; c < 3; ++c) {
        const double expected = conductor_albedo(alpha, eta[size_t(c)], k[size_t(c)], kPi / 4);
        EXPECT_NEAR(m.mean[c], expected, 4 * m.standard_error[c] + 1e-3 * expected)
            << "alpha " << alpha << ", light_sampling " << light_sampling << ", channel " << c;
      }
    }
  }
}

// A marble ball under lights `lights` whose dielectric boundary has roughness `roughness`.
std::string marble_ball(double roughness, const std::string& lights, int spp) {
  return fmt::format(
      R"({{"film": {{"width": 16, "height": 16}},
  "camera": {{"from": [0, 1.5, 4], "to": [0, -0.2, 0], "fov": 40}},
  "integrator": {{"spp": {}, "seed": 3, "sampler": "independent"}},
  "lights": {},
  "shapes": {{"ball": {{"type": "sphere", "radius": 0.8}},
             "floor": {{"type": "box", "min": [-4, -1.3, -4], "max": [4, -0.8, 4]}}}},
  "media": {{"marble": {{"sigma_a": [0.02, 0.04, 0.08], "sigma_s": [2, 2.5, 3],
                         "density": {{"type": "constant"}}}}}},
  "objects": [
    {{"shape": "ball", "medium": "marble",
      "surface": {{"type": "dielectric", "ior": 1.5, "roughness": {}}}}},
    {{"shape": "floor", "surface": {{"type": "diffuse", "albedo": 0.5}}}}]}})",
      spp, lights, roughness);
}

// At a roughness of 0.001 the rough boundary's sampling is all but the smooth one's, and its
// next-event estimation all but useless: the image is the smooth boundary's (which manifold
// sampling lights from inside) within the noise.
TEST(GlossyRender, NearlySmoothDielectricGivesTheSmoothImage) {
  const std::string light =
      R"([{"type": "sphere", "center": [-1.5, 2.5, 1.5], "radius": 0.9, "radiance": [6, 5.5, 5]}])";
  test::expect_blocks_agree(render_text(marble_ball(0.001, light, 128)).film,
                            render_text(marble_ball(0, light, 128)).film, 16,
                            "roughness 0.001 against 0");
}

// A point light reaches the inside of a rough translucent ball only through next-event
// estimation at its boundary; a sphere light of radius r and radiance I / (π r²), small enough
// that its image differs from the point light's by far less than the noise, is also found by
// sampling the boundary's lobe, weighted by MIS. The two images agree.
TEST(GlossyRender, PointLightThroughARoughBoundaryAsASmallSphereLight) {
  const double r = 0.02, intensity = 20;
  const std::string point = fmt::format(
      R"([{{"type": "point", "position": [-1.5, 2.5, 1.5], "intensity": {}}}])", intensity);
  const std::string sphere = fmt::format(
      R"([{{"type": "sphere", "center": [-1.5, 2.5, 1.5], "radius": {}, "radiance": {}}}])", r,
      intensity / (kPi * r * r));
  const RenderResult a = render_text(marble_ball(0.3, point, 64)),
                     b = render_text(marble_ball(0.3, sphere, 64));
  test::expect_blocks_agree(a.film, b.film, 16, "point light against a sphere light");
  // The ball is lit: its centre block is far from black.
  const MeanEstimate centre = region_mean(a.film, test::block_pixels(4, 4, 16));
  EXPECT_GT(centre.mean[0], 10 * centre.standard_error[0]);
}

}  // namespace
}  // namespace nimbus
