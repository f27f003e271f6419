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
#include "nimbus/render/microfacet_albedo.h"
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

// A flat rough gold-coloured conductor, single scattering only, seen at 45° through an
// orthographic camera under a sky of radiance 1: every pixel is the albedo at 45°, with the sky
// sampled by BSDF sampling alone (light_sampling "one" leaves a constant sky to it) and by both
// techniques under MIS ("all").
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
      "multiple_scattering": false, "eta": [{}, {}, {}], "k": [{}, {}, {}]}}}}]}})",
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

// The multiple-scattering lobe's table (render/microfacet_albedo.h) holds the single-scattering
// albedo: at α = 1 and 45° the F = 1 conductor's is 0.37678 by quadrature (microfacet_test.cpp);
// the table, from 1 024 stratified samples per node and linear interpolation between nodes 1/32
// apart, is within 0.005 of it, and within 0.002 of the quadrature above at its nodes.
TEST(GlossyAlbedo, TableHoldsTheSingleScatteringAlbedo) {
  Surface s;
  s.type = Surface::Type::Conductor;
  s.roughness = 1;
  const MicrofacetAlbedo t = microfacet_albedo(s);
  EXPECT_NEAR(t.outside.at(std::cos(kPi / 4)), 0.37678, 0.005);
  for (const int node : {8, 20, 32}) {
    const double mu = node / 32.0;
    EXPECT_NEAR(t.outside.E[size_t(node)], conductor_albedo(1, 1, 1e4, std::acos(mu)), 0.002)
        << "mu " << mu;
  }
  EXPECT_NEAR(t.outside.reflected, 1.0, 1e-12);
  EXPECT_GT(t.outside.average, 0.3);
  EXPECT_LT(t.outside.average, 0.6);
}

// A white furnace: a rough object that absorbs nothing, under a sky of radiance 1 and nothing
// else, is invisible; every pixel is 1. `surface` is the object's surface (JSON), `medium` its
// medium's (JSON) or empty. Returns the image's mean and its standard error in channel 0, after
// checking every 8 × 8 block against 1 within 4 standard errors plus `slack`.
MeanEstimate furnace(const std::string& surface, const std::string& medium, double slack) {
  const std::string text = fmt::format(
      R"({{"film": {{"width": 16, "height": 16}},
  "camera": {{"type": "orthographic", "from": [0, 0, 5], "to": [0, 0, 0], "width": 2}},
  "integrator": {{"spp": 64, "seed": 9, "sampler": "independent", "max_depth": 100000}},
  "lights": [{{"type": "environment", "radiance": 1}}],
  "shapes": {{"ball": {{"type": "sphere", "radius": 0.9}}}},
  "media": {{"m": {}}},
  "objects": [{{"shape": "ball", {} "surface": {}}}]}})",
      medium.empty() ? R"({"sigma_a": 0, "sigma_s": 0, "density": {"type": "constant"}})" : medium,
      medium.empty() ? "" : R"("medium": "m",)", surface);
  const RenderResult r = render_text(text);
  for (int by = 0; by < 16; by += 8)
    for (int bx = 0; bx < 16; bx += 8) {
      const MeanEstimate m = region_mean(r.film, test::block_pixels(bx, by, 16));
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(m.mean[c], 1.0, 4 * m.standard_error[c] + slack)
            << surface << ": block (" << bx << ", " << by << ") channel " << c;
    }
  std::vector<int> all(256);
  for (int p = 0; p < 256; ++p) all[size_t(p)] = p;
  return region_mean(r.film, all);
}

// A rough conductor that reflects everything (k = 10⁴: F = 1 to 4e-8) and a rough dielectric
// around a medium of albedo 1 conserve energy with the multiple-scattering lobe: every block is 1
// within 1 % (and 4 standard errors). Without it they lose energy, which the test records.
TEST(GlossyRender, WhiteFurnaceWithMultipleScattering) {
  for (const double alpha : {0.05, 0.5, 1.0}) {
    furnace(fmt::format(R"({{"type": "conductor", "eta": 1, "k": 10000, "roughness": {}}})", alpha),
            "", 0.01);
    furnace(fmt::format(R"({{"type": "dielectric", "ior": 1.5, "roughness": {}}})", alpha),
            R"({"sigma_a": 0, "sigma_s": 2, "density": {"type": "constant"}})", 0.01);
  }
  // Single scattering alone: the conductor at α = 1 reflects 0.31–0.67 of the light (the
  // microfacet tests' albedos), so the image, sky around the ball included, is far below 1.
  const MeanEstimate single = furnace(
      R"({"type": "conductor", "eta": 1, "k": 10000, "roughness": 1, "multiple_scattering": false})",
      "", 1.0);
  EXPECT_LT(single.mean[0], 0.8);
  // The rough dielectric around the white medium at α = 1 without it: 0.58 (sky included).
  const MeanEstimate single_dielectric =
      furnace(R"({"type": "dielectric", "ior": 1.5, "roughness": 1, "multiple_scattering": false})",
              R"({"sigma_a": 0, "sigma_s": 2, "density": {"type": "constant"}})", 1.0);
  EXPECT_LT(single_dielectric.mean[0], 0.8);
}

// A roughness that a texture drives from 0.05 to 1 takes its multiple-scattering lobe from tables
// blended between roughnesses (microfacet_albedo.h): the white furnace stays within 1 %.
TEST(GlossyRender, WhiteFurnaceWithATexturedRoughness) {
  furnace(R"({"type": "conductor", "eta": 1, "k": 10000, "roughness": {
      "texture": {"type": "noise", "frequency": 3}, "from": 0.05, "to": 1}})",
          "", 0.01);
  furnace(R"({"type": "dielectric", "ior": 1.5, "roughness": {
      "texture": {"type": "veins", "frequency": 2}, "from": 0.05, "to": 1}})",
          R"({"sigma_a": 0, "sigma_s": 2, "density": {"type": "constant"}})", 0.01);
}

}  // namespace
}  // namespace nimbus
