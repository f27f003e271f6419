// Manifold next-event estimation (render/manifold.h, render/manifold_light.h): the walk against
// Snell's law and closed-form generalized geometry terms, its failures on degenerate boundaries,
// and renders with it on against renders with it off (where BSDF and phase sampling alone find
// the same light), and against delta lights as area lights shrink.

#include "nimbus/render/manifold.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "nimbus/math/constants.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "support/film_blocks.h"

namespace nimbus {
namespace {

using test::block_pixels;
using test::expect_blocks_agree;

Scene scene_from(const std::string& text, const std::vector<std::string>& overrides = {}) {
  return compile_scene(load_scene_text(text, "manifold_test", overrides));
}

// A glass solid of shape `shape` (JSON) holding `medium` (JSON, or empty for none), over a grey
// diffuse floor whose top is at y = `floor_y`, lit by `lights` (a JSON array); a size × size
// image through a camera at `from` looking at the origin, rendered by the independent sampler
// (whose per-pixel variances estimate the variance of each pixel's mean).
std::string glass_scene(
    const std::string& shape, const std::string& medium, double floor_y, const std::string& lights,
    int size, int spp,
    const char* camera = R"("from": [0, 1.5, 4], "to": [0, -0.2, 0], "fov": 40)") {
  return fmt::format(
      R"({{"film": {{"width": {0}, "height": {0}}},
  "camera": {{{1}}},
  "integrator": {{"spp": {2}, "seed": 3, "sampler": "independent"}},
  "lights": {3},
  "shapes": {{"solid": {4},
             "floor": {{"type": "box", "min": [-4, {5}, -4], "max": [4, {6}, 4]}}}},
  "media": {{"m": {7}}},
  "objects": [
    {{"shape": "solid", {8} "surface": {{"type": "dielectric", "ior": 1.5}}}},
    {{"shape": "floor", "surface": {{"type": "diffuse", "albedo": 0.5}}}}
  ]}})",
      size, camera, spp, lights, shape, floor_y - 0.5, floor_y,
      medium.empty()
          ? R"({"sigma_a": [0, 0, 0], "sigma_s": [0, 0, 0], "density": {"type": "constant"}})"
          : medium,
      medium.empty() ? "" : R"("medium": "m",)");
}

const std::string kSphere = R"({"type": "sphere", "center": [0, 0, 0], "radius": 0.8})";
const std::string kMarble =
    R"({"sigma_a": [0.05, 0.1, 0.2], "sigma_s": [2, 3, 4], "density": {"type": "constant"}})";

// The refraction of unit direction d at unit normal n (either side), from index eta_i to eta_t.
Vec3 refract(const Vec3& d, const Vec3& n, double eta_i, double eta_t) {
  const Vec3 nf = dot(d, n) < 0 ? n : -n;
  const double cos_i = -dot(d, nf), eta = eta_t / eta_i;
  const double cos_t = std::sqrt(1 - (1 - cos_i * cos_i) / (eta * eta));
  return normalize(d / eta + nf * (cos_i / eta - cos_t));
}

void expect_near(const Vec3& a, const Vec3& b, double tol, const char* what) {
  EXPECT_NEAR(a.x, b.x, tol) << what;
  EXPECT_NEAR(a.y, b.y, tol) << what;
  EXPECT_NEAR(a.z, b.z, tol) << what;
}

const char* kSun = R"([{"type": "directional", "direction": [-0.4, -1, -0.3], "irradiance": 2}])";

TEST(ManifoldWalk, OneRefractionObeysSnellsLaw) {
  const Scene scene = scene_from(glass_scene(kSphere, kMarble, -0.8, kSun, 8, 1));
  const ChainStart start{{0.3, -0.2, 0.1}, {}, false, 0};
  for (const ChainTarget& target :
       {ChainTarget{{}, normalize(Vec3{1, 2, 0.5}), true}, ChainTarget{{2, 3, -1}, {}, false}}) {
    const auto shape = chain_shape(scene, start, target);
    ASSERT_TRUE(shape);
    EXPECT_EQ(shape->solid, 0);
    EXPECT_EQ(shape->vertices, 1);
    ManifoldCounters counters;
    const auto chain = solve_chain(scene, start, target, *shape,
                                   seed_chain(scene, start, target, *shape), counters);
    ASSERT_TRUE(chain);
    EXPECT_EQ(counters.walks, 1u);
    EXPECT_EQ(counters.found, 1u);
    const Vec3 x = chain->x[0];
    EXPECT_NEAR(length(x), 0.8, 1e-12);
    expect_near(chain->dir0, normalize(x - start.p), 1e-12, "first direction");
    const Vec3 to_light = target.at_infinity ? target.direction : normalize(target.point - x);
    expect_near(chain->dir_out, to_light, 1e-9, "leaves towards the light");
    expect_near(refract(chain->dir0, normalize(x), 1.5, 1), to_light, 1e-9, "Snell's law");
    const double cos_i = dot(chain->dir0, normalize(x));
    EXPECT_NEAR(chain->transmission, 1 - fresnel_dielectric(cos_i, 1 / 1.5), 1e-12);
  }
}

TEST(ManifoldWalk, TwoRefractionsThroughABall) {
  const Scene scene = scene_from(glass_scene(kSphere, "", -0.8, kSun, 8, 1));
  // A floor point under the ball, in its shadow: the sun reaches it through the glass.
  const ChainStart start{{-0.27, -0.8, -0.21}, {0, 1, 0}, true, -1};
  const ChainTarget target{{}, normalize(Vec3{0.4, 1, 0.3}), true};
  const auto shape = chain_shape(scene, start, target);
  ASSERT_TRUE(shape);
  EXPECT_EQ(shape->vertices, 2);
  ManifoldCounters counters;
  const auto chain =
      solve_chain(scene, start, target, *shape, seed_chain(scene, start, target, *shape), counters);
  ASSERT_TRUE(chain);
  const Vec3 x0 = chain->x[0], x1 = chain->x[1];
  EXPECT_NEAR(length(x0), 0.8, 1e-12);
  EXPECT_NEAR(length(x1), 0.8, 1e-12);
  const Vec3 inside = refract(chain->dir0, normalize(x0), 1, 1.5);
  // The ray inside starts a hair off the boundary (offset_origin: 1e-7 of the scene's size), as
  // the path tracer's do, so x0 → x1 turns from the refracted direction by about that much.
  expect_near(inside, normalize(x1 - x0), 1e-6, "first refraction");
  expect_near(refract(inside, normalize(x1), 1.5, 1), target.direction, 1e-9, "second refraction");
  expect_near(chain->dir_out, target.direction, 1e-9, "leaves towards the sun");
}

// Through a flat face the generalized geometry term is closed-form: solid angle scales across
// a refraction as η² cos θ dω (radiance invariance), so |dω₀/dω_out| = cos θ_out / (η² cos θ₀).
TEST(ManifoldWalk, GeometryTermThroughAFlatFace) {
  const std::string box = R"({"type": "box", "min": [-3, -2, -3], "max": [3, 0.5, 3]})";
  const Scene scene = scene_from(glass_scene(box, kMarble, -2, kSun, 8, 1));
  const ChainStart start{{0.2, 0.1, -0.3}, {}, false, 0};
  for (const double out_deg : {0.0, 20.0, 50.0, 80.0}) {
    const double a = out_deg * kPi / 180;
    const ChainTarget target{{}, {std::sin(a), std::cos(a), 0}, true};
    const auto shape = chain_shape(scene, start, target);
    ASSERT_TRUE(shape);
    ManifoldCounters counters;
    const auto chain = solve_chain(scene, start, target, *shape,
                                   seed_chain(scene, start, target, *shape), counters);
    ASSERT_TRUE(chain) << out_deg;
    EXPECT_NEAR(chain->x[0].y, 0.5, 1e-12);
    const double cos_out = std::cos(a), cos_0 = chain->dir0.y;
    EXPECT_NEAR(std::sqrt(1 - cos_0 * cos_0) * 1.5, std::sin(a), 1e-9) << out_deg;
    const double expected = cos_out / (1.5 * 1.5 * cos_0);
    EXPECT_NEAR(chain->jacobian / expected, 1, 1e-6) << out_deg;
  }
}

// From a ball's centre every ray leaves along the normal, unbent: a target point at distance D
// from the centre gives |dω₀/dA⊥| = 1 / D².
TEST(ManifoldWalk, GeometryTermFromTheCentre) {
  const Scene scene = scene_from(glass_scene(kSphere, kMarble, -0.8, kSun, 8, 1));
  const ChainStart start{{0, 0, 0}, {}, false, 0};
  const ChainTarget target{{1, 2.5, -1.2}, {}, false};
  const auto shape = chain_shape(scene, start, target);
  ASSERT_TRUE(shape);
  ManifoldCounters counters;
  const auto chain =
      solve_chain(scene, start, target, *shape, seed_chain(scene, start, target, *shape), counters);
  ASSERT_TRUE(chain);
  const double d2 = dot(target.point, target.point);
  EXPECT_NEAR(chain->jacobian * d2, 1, 1e-6);
  EXPECT_NEAR(chain->transmission, 1 - fresnel_dielectric(1, 1 / 1.5), 1e-12);
}

// F = x² − y² + x³ (a saddle quadric and two cubed half-spaces) has ∇F = 0 at the origin, which
// lies on its surface, and a ray along (1, 1, 0) crosses the surface there. A walk aimed at it
// fails or finds a finite chain; it is counted either way, and renders stay finite.
const std::string kSaddle = R"({"type": "intersection", "shapes": [
    {"type": "sphere", "radius": 0.8},
    {"type": "freeform",
     "base": {"type": "quadric", "coefficients": [1, -1, 0, 0, 0, 0, 0, 0, 0, 0]},
     "perturbations": [
       {"shape": {"type": "halfspace", "normal": [-1, 0, 0]}, "weight": 1},
       {"shape": {"type": "halfspace", "normal": [1, 0, 0]}, "weight": -1}]}]})";

TEST(ManifoldWalk, DegenerateBoundaryFailsCleanly) {
  const Scene scene = scene_from(glass_scene(kSaddle, kMarble, -0.8, kSun, 8, 1));
  const ChainStart start{{-0.3, -0.3, 0}, {}, false, -1};
  const ChainTarget target{{}, normalize(Vec3{1, 1, 0}), true};
  const auto shape = chain_shape(scene, start, target);
  ASSERT_TRUE(shape);
  ManifoldCounters counters;
  const auto chain =
      solve_chain(scene, start, target, *shape, seed_chain(scene, start, target, *shape), counters);
  EXPECT_EQ(counters.walks, 1u);
  if (chain) {
    EXPECT_TRUE(std::isfinite(chain->jacobian));
    EXPECT_TRUE(std::isfinite(chain->dir0.x + chain->dir0.y + chain->dir0.z));
  }
  const std::string lights = R"([{"type": "directional", "direction": [-1, -1, 0], "irradiance": 2},
      {"type": "point", "position": [0.6, 0.6, 0.2], "intensity": 1}])";
  const Scene render_me = scene_from(glass_scene(
      kSaddle, kMarble, -0.8, lights, 16, 4, R"("from": [2, 2, 2], "to": [0, 0, 0], "fov": 40)"));
  RenderOptions options;
  options.threads = 1;
  const RenderResult r = render(render_me, options);
  EXPECT_EQ(r.counters.rejected_samples, 0u);
  EXPECT_GT(r.counters.manifold.walks, r.counters.manifold.found);
  for (int p = 0; p < 16 * 16; ++p)
    for (int c = 0; c < 3; ++c) EXPECT_TRUE(std::isfinite(r.film.mean(p)[c])) << p;
}

RenderResult render_with(const std::string& text, bool manifold,
                         std::vector<std::string> overrides = {}) {
  RenderOptions options;
  options.threads = 2;
  overrides.push_back(fmt::format("integrator.manifold={}", manifold));
  return render(scene_from(text, overrides), options);
}

// Where both apply (a sphere light of finite size), manifold sampling and BSDF or phase sampling
// alone estimate the same image; MIS keeps them from counting a path twice.
void expect_same_image_on_and_off(const std::string& text, int size, const char* what,
                                  const std::vector<std::string>& overrides = {}) {
  const RenderResult on = render_with(text, true, overrides),
                     off = render_with(text, false, overrides);
  EXPECT_GT(on.counters.manifold.found, 0u) << what;
  EXPECT_GT(on.counters.manifold.checks, 0u) << what;  // MIS weighed some light hits
  EXPECT_EQ(off.counters.manifold.walks, 0u) << what;
  expect_blocks_agree(on.film, off.film, size, what);
}

const char* kSphereLight =
    R"([{"type": "sphere", "center": [-1.5, 2.5, 1.5], "radius": 0.9, "radiance": [6, 5.5, 5]}])";

TEST(ManifoldRender, MarbleSphereOnAndOffAgree) {
  expect_same_image_on_and_off(glass_scene(kSphere, kMarble, -0.8, kSphereLight, 16, 256), 16,
                               "marble sphere");
}

// Spectral mode, with plain spectral tracking (one throughput) rather than spectral MIS.
TEST(ManifoldRender, MarbleSphereOnAndOffAgreeInSpectralMode) {
  expect_same_image_on_and_off(glass_scene(kSphere, kMarble, -0.8, kSphereLight, 16, 128), 16,
                               "marble sphere, spectral",
                               {R"(spectrum.mode="spectral")", "spectrum.wavelengths=4",
                                R"(integrator.tracking="spectral-history")"});
}

TEST(ManifoldRender, FreeFormWithFourPerturbationsOnAndOffAgree) {
  const std::string blob = R"({"type": "freeform",
      "base": {"type": "sphere", "radius": 0.7},
      "perturbations": [
        {"shape": {"type": "sphere", "center": [0.5, 0.2, 0], "radius": 0.35}, "weight": 8},
        {"shape": {"type": "sphere", "center": [-0.4, 0.3, 0.2], "radius": 0.3}, "weight": 8},
        {"shape": {"type": "sphere", "center": [0, 0.6, -0.2], "radius": 0.3}, "weight": 6},
        {"shape": {"type": "sphere", "center": [0.1, -0.1, 0.55], "radius": 0.25}, "weight": -10}]})";
  expect_same_image_on_and_off(glass_scene(blob, kMarble, -0.75, kSphereLight, 16, 256), 16,
                               "free form");
}

TEST(ManifoldRender, GlassBallCausticOnAFloorOnAndOffAgree) {
  // An empty glass ball, seen from above: its shadow on the floor is lit through two
  // refractions, a caustic brighter than the floor in the light.
  const char* light =
      R"([{"type": "sphere", "center": [-0.7, 2.2, -0.4], "radius": 0.5, "radiance": [3, 3, 3]}])";
  const char* camera = R"("from": [0.6, 3.2, 0.9], "to": [0.55, -0.8, 0.3], "fov": 30)";
  const std::string text = glass_scene(kSphere, "", -0.8, light, 16, 256, camera);
  expect_same_image_on_and_off(text, 16, "glass ball caustic");
  // Without area caustics the caustic is left to BSDF sampling: no walk, the same image.
  const RenderResult no_caustics =
      render_with(text, true, {"integrator.manifold_area_caustics=false"});
  EXPECT_EQ(no_caustics.counters.manifold.walks, 0u);
  expect_blocks_agree(no_caustics.film, render_with(text, false).film, 16,
                      "glass ball caustic, no walks");
}

// `text` (a glass_scene) with an emissive surface of shape `shape` (JSON) added.
std::string with_lamp(std::string text, const std::string& shape, const std::string& radiance) {
  const auto insert_after = [&](const std::string& key, const std::string& what) {
    const size_t at = text.find(key);
    EXPECT_NE(at, std::string::npos) << key;
    text.insert(at + key.size(), what);
  };
  insert_after(R"("shapes": {)", R"("lamp": )" + shape + ",");
  insert_after(
      R"("objects": [)",
      R"({"shape": "lamp", "surface": {"type": "emissive", "radiance": )" + radiance + "}},");
  return text;
}

// Emissive surfaces are targets too (render/emitter.h): a marble ball lit by an emissive box, and
// a glass ball's caustic from an emissive ball, on and off.
TEST(ManifoldRender, EmissiveSurfacesOnAndOffAgree) {
  const std::string box = R"({"type": "box", "min": [-1.9, 2.1, 1.0], "max": [-1.1, 2.9, 2.0]})";
  expect_same_image_on_and_off(
      with_lamp(glass_scene(kSphere, kMarble, -0.8, "[]", 16, 256), box, "[6, 5.5, 5]"), 16,
      "marble sphere under an emissive box");
  const char* camera = R"("from": [0.6, 3.2, 0.9], "to": [0.55, -0.8, 0.3], "fov": 30)";
  expect_same_image_on_and_off(
      with_lamp(glass_scene(kSphere, "", -0.8, "[]", 16, 256, camera),
                R"({"type": "sphere", "center": [-0.7, 2.2, -0.4], "radius": 0.5})", "3"),
      16, "glass ball caustic from an emissive ball");
}

// The sum over pixels and channels of the estimated variance of each pixel's mean.
double image_variance(const Film& film, int size) {
  double v = 0;
  for (int p = 0; p < size * size; ++p) {
    const MeanEstimate m = region_mean(film, {p});
    for (int c = 0; c < 3; ++c) v += m.standard_error[c] * m.standard_error[c];
  }
  return v;
}

// A glass ball mirrors a small sphere light, an emissive ball and the sky (render/mirror_light.h):
// probing the mirror direction at every sample that meets the glass from outside gives the
// image that sampling the reflection alone gives, with far less variance where the camera sees
// the lights reflected.
TEST(ManifoldRender, MirrorImagesOfLightsOnAndOffAgree) {
  const int size = 16;
  const std::string text = fmt::format(
      R"({{"film": {{"width": {0}, "height": {0}}},
  "camera": {{"from": [0, 1.5, 4], "to": [0, -0.2, 0], "fov": 40}},
  "integrator": {{"spp": 256, "seed": 5, "sampler": "independent"}},
  "lights": [{{"type": "environment", "radiance": [0.2, 0.25, 0.3]}},
             {{"type": "sphere", "center": [1.5, 3, 4], "radius": 0.3, "radiance": [60, 55, 50]}}],
  "shapes": {{"ball": {1}, "lamp": {{"type": "sphere", "center": [-1.5, 2, 3.5], "radius": 0.3}},
             "floor": {{"type": "box", "min": [-4, -1.3, -4], "max": [4, -0.8, 4]}}}},
  "objects": [
    {{"shape": "ball", "surface": {{"type": "dielectric", "ior": 1.5}}}},
    {{"shape": "lamp", "surface": {{"type": "emissive", "radiance": [10, 20, 30]}}}},
    {{"shape": "floor", "surface": {{"type": "diffuse", "albedo": 0.5}}}}
  ]}})",
      size, kSphere);
  const RenderResult on = render_with(text, true), off = render_with(text, false);
  EXPECT_GT(on.counters.manifold.mirror_probes, 0u);
  EXPECT_EQ(off.counters.manifold.mirror_probes, 0u);
  expect_blocks_agree(on.film, off.film, size, "mirror images");
  const double v_on = image_variance(on.film, size), v_off = image_variance(off.film, size);
  EXPECT_LT(v_on, v_off) << v_on << " vs " << v_off;
}

// A sphere light and a diffuse slab inside a fog-filled glass ball: next-event estimation from
// inside reaches the light by a straight shadow ray, which the walk leaves alone, and phase and
// BSDF sampling's hits of it carry the matching MIS weight.
TEST(ManifoldRender, LightInsideASolidOnAndOffAgree) {
  const int size = 16;
  const std::string text = fmt::format(
      R"({{"film": {{"width": {0}, "height": {0}}},
  "camera": {{"from": [0, 2.5, 2.5], "to": [0, -0.3, 0], "fov": 24}},
  "integrator": {{"spp": 256, "seed": 3, "sampler": "independent"}},
  "lights": [{{"type": "sphere", "center": [0.3, 0.5, 0.2], "radius": 0.15, "radiance": 20}}],
  "shapes": {{"ball": {{"type": "sphere", "radius": 1.2}},
             "slab": {{"type": "box", "min": [-0.8, -0.5, -0.8], "max": [0.8, -0.3, 0.8]}}}},
  "media": {{"fog": {1}}},
  "objects": [
    {{"shape": "ball", "medium": "fog", "surface": {{"type": "dielectric", "ior": 1.3}}}},
    {{"shape": "slab", "surface": {{"type": "diffuse", "albedo": 0.7}}}}
  ]}})",
      size, R"({"sigma_a": 0.05, "sigma_s": 0.5, "density": {"type": "constant"}})");
  expect_blocks_agree(render_with(text, true).film, render_with(text, false).film, size,
                      "light inside a solid");
}

// The largest disagreement of two films over their 8 x 8 blocks and channels, in standard errors
// of the difference of the block means.
double largest_block_z(const Film& a, const Film& b, int size) {
  double z = 0;
  for (int by = 0; by < size; by += 8)
    for (int bx = 0; bx < size; bx += 8) {
      const std::vector<int> pixels = block_pixels(bx, by, size);
      const MeanEstimate ma = region_mean(a, pixels), mb = region_mean(b, pixels);
      for (int c = 0; c < 3; ++c)
        z = std::max(z, std::abs(ma.mean[c] - mb.mean[c]) /
                            std::hypot(ma.standard_error[c], mb.standard_error[c]));
    }
  return z;
}

// Renders of a marble ball lit by lights[0..2] (area lights shrinking by 4 each time) against
// the delta light they tend to: the largest block's disagreement shrinks, and at the smallest
// is within 4 standard errors. Only manifold sampling lights the ball's inside by a delta light.
void expect_limit(const std::array<std::string, 3>& shrinking, const std::string& delta,
                  const char* what) {
  const int size = 16;
  const auto film = [&](const std::string& light) {
    return render_with(glass_scene(kSphere, kMarble, -0.8, "[" + light + "]", size, 256), true)
        .film;
  };
  const Film limit = film(delta);
  double z[3];
  for (int i = 0; i < 3; ++i) z[i] = largest_block_z(film(shrinking[size_t(i)]), limit, size);
  EXPECT_GT(z[0], 4) << what << ": the largest light should differ from the delta light (" << z[0]
                     << ", " << z[1] << ", " << z[2] << ")";
  EXPECT_LT(z[1], z[0]) << what;
  EXPECT_LT(z[2], 4) << what << " (" << z[0] << ", " << z[1] << ", " << z[2] << ")";
}

// A sphere light of radius r and radiance I / (π r²) has the point light's intensity I.
TEST(ManifoldRender, ShrinkingSphereLightsTendToThePointLight) {
  std::array<std::string, 3> spheres;
  for (int i = 0; i < 3; ++i) {
    const double r = 1.2 / std::pow(4.0, i), L = 8 / (kPi * r * r);
    spheres[size_t(i)] = fmt::format(
        R"({{"type": "sphere", "center": [-1.2, 1.6, 0.8], "radius": {}, "radiance": {}}})", r, L);
  }
  expect_limit(spheres, R"({"type": "point", "position": [-1.2, 1.6, 0.8], "intensity": 8})",
               "point light");
}

// A distant sphere light of angular radius α and radiance E / (π sin² α) gives the directional
// light's irradiance E: the narrowing cones of directions tend to it.
TEST(ManifoldRender, NarrowingConesTendToTheDirectionalLight) {
  const Vec3 towards = normalize(Vec3{-1, 1.6, 0.5});
  const double distance = 200;
  std::array<std::string, 3> suns;
  for (int i = 0; i < 3; ++i) {
    const double alpha = 40 * kPi / 180 / std::pow(4.0, i), s = std::sin(alpha);
    const Vec3 c = towards * distance;
    suns[size_t(i)] =
        fmt::format(R"({{"type": "sphere", "center": [{}, {}, {}], "radius": {}, "radiance": {}}})",
                    c.x, c.y, c.z, distance * s, 2 / (kPi * s * s));
  }
  expect_limit(
      suns,
      fmt::format(R"({{"type": "directional", "direction": [{}, {}, {}], "irradiance": 2}})",
                  -towards.x, -towards.y, -towards.z),
      "directional light");
}

}  // namespace
}  // namespace nimbus
