// Solid textures (media/pattern_density.h, media/texture.h): the patterns are the functions they
// say; a textured albedo under a uniform sky gives albedo × radiance at each point; a textured
// absorber transmits exp(−∫σ_a) along each ray, integrated here by quadrature, under majorants
// that bound it; a textured white medium and a textured rough boundary conserve energy.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "nimbus/math/constants.h"
#include "nimbus/math/mat4.h"
#include "nimbus/math/rng.h"
#include "nimbus/media/noise.h"
#include "nimbus/media/pattern_density.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "support/film_chi2.h"
#include "support/pixel_references.h"
#include "support/process.h"
#include "support/stats.h"

namespace nimbus {
namespace {

RenderResult render_text(const std::string& text) {
  RenderOptions options;
  options.threads = 2;
  return render(compile_scene(load_scene_text(text, "texture_test")), options);
}

Vec3 random_point(Rng& rng, double half) {
  return {half * (2 * rng.uniform() - 1), half * (2 * rng.uniform() - 1),
          half * (2 * rng.uniform() - 1)};
}

// Perlin's marble without turbulence: ((1 + sin(2π f d·x)) / 2)^p.
double sine_bands(double f, const Vec3& d, double p, const Vec3& x) {
  return std::pow(0.5 * (1 + std::sin(2 * kPi * f * dot(d, x))), p);
}

TEST(Patterns, VeinsWithoutTurbulenceAreSineBands) {
  PatternParams p;
  p.kind = PatternParams::Kind::Veins;
  p.frequency = 1.5;
  p.direction = normalize(Vec3{1, 2, 2});
  p.turbulence = 0;
  p.sharpness = 3;
  const DensityPtr veins = make_pattern_density(p);
  Rng rng(7, 0);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 x = random_point(rng, 4);
    EXPECT_NEAR(veins->value(x, 0.0), sine_bands(1.5, p.direction, 3, x), 1e-12);
  }
}

TEST(Patterns, TurbulenceOfOneOctaveIsTheNoiseMagnitude) {
  PatternParams p;
  p.kind = PatternParams::Kind::Turbulence;
  p.frequency = 2.5;
  p.octaves = 1;
  p.seed = 11;
  const DensityPtr turbulence = make_pattern_density(p);
  const Noise n = make_noise(11);
  Rng rng(8, 0);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 x = random_point(rng, 4);
    EXPECT_DOUBLE_EQ(turbulence->value(x, 0.0), std::min(1.0, std::abs(noise(n, 2.5 * x))));
  }
}

// Every pattern stays in [0, 1], its range over any box, and varies: a texture that was
// constant, or a seed that changed nothing, would fail.
TEST(Patterns, StayInTheUnitIntervalVaryAndFollowTheirSeed) {
  using K = PatternParams::Kind;
  for (const K kind : {K::Noise, K::Turbulence, K::Veins}) {
    SCOPED_TRACE(static_cast<int>(kind));
    PatternParams p;
    p.kind = kind;
    p.frequency = 1.3;
    const DensityPtr a = make_pattern_density(p);
    p.seed = 1;
    const DensityPtr b = make_pattern_density(p);
    const Interval range = a->range(Box{{-5, -5, -5}, {5, 5, 5}}, Interval::point(1.0));
    Rng rng(9, 0);
    double sum = 0, sum2 = 0;
    int differ = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      const Vec3 x = random_point(rng, 5);
      const double v = a->value(x, 0.0);
      ASSERT_GE(v, range.lo);
      ASSERT_LE(v, range.hi);
      sum += v;
      sum2 += v * v;
      differ += std::abs(v - b->value(x, 0.0)) > 1e-3;
    }
    EXPECT_EQ(range.lo, 0.0);
    EXPECT_EQ(range.hi, 1.0);
    const double mean = sum / n;
    EXPECT_GT(std::sqrt(sum2 / n - mean * mean), 0.05);
    EXPECT_GT(differ, n / 2);
  }
}

// A diffuse floor whose albedo blends from 0.2 to 0.8 by sine bands (veins without turbulence),
// seen from above through an orthographic camera, under a sky of radiance 1: each pixel is the
// mean over its footprint of the albedo at the points it sees (the sky fills the hemisphere of
// every point of the top face). The reference comes from the bands' formula at the point in the
// floor's own coordinates, to_object(x); a floor whose albedo runs from 0.25 fails the same test,
// and so does a placed floor whose bands stayed in the scene's coordinates.
void expect_textured_floor(const std::string& transform, const std::string& instances,
                           const Mat4& to_object) {
  SCOPED_TRACE(transform + instances);
  const std::string text = fmt::format(R"({{"film": {{"width": 16, "height": 16}},
  "camera": {{"type": "orthographic", "from": [0, 3, 0], "to": [0, 0, 0], "up": [0, 0, -1],
             "width": 2}},
  "integrator": {{"spp": 64, "seed": 3}},
  "lights": [{{"type": "environment", "radiance": 1}}],
  "shapes": {{"slab": {{"type": "box", "min": [-20, -1, -20], "max": [20, 0, 20]{}}}}},
  "objects": [{{"shape": "slab", {}"surface": {{"type": "diffuse", "albedo": {{
      "texture": {{"type": "veins", "frequency": 0.8, "direction": [1, 0, 0.5], "turbulence": 0,
                  "sharpness": 2}},
      "from": 0.2, "to": 0.8}}}}}}]}})",
                                       transform, instances);
  const Scene scene = compile_scene(load_scene_text(text, "texture_test"));
  const RenderResult r = render_text(text);
  const Vec3 d = normalize(Vec3{1, 0, 0.5});
  auto reference = [&](double from, const Mat4& frame) {
    return test::pixel_references(scene.camera, 16, 16, 16, [&](const Ray& ray) {
      const Vec3 x = ray.at(-ray.o.y / ray.d.y);
      return Rgb(from + (0.8 - from) * sine_bands(0.8, d, 2, transform_point(frame, x)));
    });
  };
  const std::vector<Rgb> ref = reference(0.2, to_object), wrong = reference(0.25, to_object);
  const test::Chi2 chi2 = test::film_chi2(r.film, [&](int p) { return ref[size_t(p)]; });
  EXPECT_EQ(chi2.dof, 16 * 16 * 3);
  EXPECT_TRUE(chi2.passes()) << "chi2 " << chi2.value << " over " << chi2.dof;
  EXPECT_FALSE(test::film_chi2(r.film, [&](int p) { return wrong[size_t(p)]; }).passes());
  if (to_object.m != Mat4::identity().m) {
    const std::vector<Rgb> in_scene = reference(0.2, Mat4::identity());
    EXPECT_FALSE(test::film_chi2(r.film, [&](int p) { return in_scene[size_t(p)]; }).passes());
  }
}

TEST(TextureRender, TexturedAlbedoUnderAUniformSkyIsAlbedoTimesRadiance) {
  expect_textured_floor("", "", Mat4::identity());
}

// The texture is a function of the object's own coordinates: it moves with the shape's
// transform, and with an instance's placement on top of it.
TEST(TextureRender, TexturesFollowTheirObjectsTransformAndInstance) {
  const std::string transform =
      R"(, "transform": [{"translate": [0.3, 0, 0.1]}, {"rotate": {"axis": [0, 1, 0], "degrees": 35}}])";
  const Mat4 shape = Mat4::rotate({0, 1, 0}, 35) * Mat4::translate({0.3, 0, 0.1});
  expect_textured_floor(transform, "", inverse(shape));
  expect_textured_floor(transform, R"("instances": [[{"translate": [0.45, 0, -0.15]}]], )",
                        inverse(Mat4::translate({0.45, 0, -0.15}) * shape));
}

// Chi-square of a size × size render against reference pixels over 3 × 3 blocks: a binary
// transmittance estimate has few hits in a dark pixel, and its per-pixel sample variance is
// then no estimate of its spread; a block's 9 pixels give it enough.
test::Chi2 block_chi2(const Film& film, int size, const std::vector<Rgb>& ref) {
  test::Chi2 c;
  for (int by = 0; by < size; by += 3)
    for (int bx = 0; bx < size; bx += 3) {
      std::vector<int> pixels;
      Rgb expected(0.0);
      for (int y = by; y < by + 3; ++y)
        for (int x = bx; x < bx + 3; ++x) {
          pixels.push_back(y * size + x);
          expected += ref[size_t(y * size + x)] / 9.0;
        }
      const MeanEstimate m = region_mean(film, pixels);
      for (int ch = 0; ch < 3; ++ch)
        test::add_z(c, m.mean[ch] - expected[ch], m.standard_error[ch] * m.standard_error[ch]);
    }
  return c;
}

// An absorbing slab (z in [-0.5, 0.5]) whose sigma_a blends from 0.2 to 3 by sine bands across
// (1, 0, 1) / √2, so that it varies along every camera ray, seen against a sky of radiance 1:
// each pixel is the mean over its footprint of exp(−∫ sigma_a dz), integrated by Simpson's rule.
// The majorants come from the texture's ends and bound it: no majorant is raised and no
// probability clamped. An absorber 10 % weaker fails.
TEST(TextureRender, TexturedAbsorberTransmitsTheExponentOfItsIntegral) {
  for (const char* tracking : {"delta", "spectral-mis"}) {
    SCOPED_TRACE(tracking);
    const std::string text = fmt::format(R"({{"film": {{"width": 12, "height": 12}},
  "camera": {{"type": "orthographic", "from": [0, 0, 5], "to": [0, 0, 0], "width": 2}},
  "integrator": {{"spp": 64, "seed": 4, "tracking": "{}"}},
  "lights": [{{"type": "environment", "radiance": 1}}],
  "shapes": {{"slab": {{"type": "box", "min": [-20, -20, -0.5], "max": [20, 20, 0.5]}}}},
  "media": {{"m": {{"sigma_s": 0, "sigma_a": {{
      "texture": {{"type": "veins", "frequency": 0.7, "direction": [1, 0, 1], "turbulence": 0,
                   "sharpness": 2}},
      "from": 0.2, "to": 3}}}}}},
  "objects": [{{"shape": "slab", "medium": "m", "surface": {{"type": "none"}}}}]}})",
                                         tracking);
    const Scene scene = compile_scene(load_scene_text(text, "texture_test"));
    const RenderResult r = render_text(text);
    const Vec3 d = normalize(Vec3{1, 0, 1});
    auto reference = [&](double scale) {
      return test::pixel_references(scene.camera, 12, 12, 8, [&](const Ray& ray) {
        const double tau = test::simpson(
            [&](double z) {
              const Vec3 x{ray.o.x, ray.o.y, z};
              return scale * (0.2 + 2.8 * sine_bands(0.7, d, 2, x));
            },
            -0.5, 0.5, 200);
        return Rgb(std::exp(-tau));
      });
    };
    const std::vector<Rgb> ref = reference(1.0), weaker = reference(0.9);
    const test::Chi2 chi2 = block_chi2(r.film, 12, ref);
    EXPECT_EQ(chi2.dof, 16 * 3);
    EXPECT_TRUE(chi2.passes()) << "chi2 " << chi2.value << " over " << chi2.dof;
    EXPECT_FALSE(block_chi2(r.film, 12, weaker).passes());
    EXPECT_EQ(r.counters.tracking.raised, 0u);
    EXPECT_EQ(r.counters.tracking.clamped, 0u);
    EXPECT_EQ(r.counters.rejected_samples, 0u);
  }
}

// A medium that scatters everything, its sigma_s blended from 0.5 to 8 by noise, in a sphere
// under a sky of radiance 1 and nothing else: every pixel is 1 (a white furnace), in every
// tracking mode, and its majorants bound it.
TEST(TextureRender, TexturedWhiteMediumIsInvisibleInAFurnace) {
  auto furnace = [](const char* tracking, double sigma_a) {
    return render_text(fmt::format(R"({{"film": {{"width": 8, "height": 8}},
  "camera": {{"type": "orthographic", "from": [0, 0, 5], "to": [0, 0, 0], "width": 2}},
  "integrator": {{"spp": 32, "seed": 5, "tracking": "{}", "max_depth": 100000}},
  "lights": [{{"type": "environment", "radiance": 1}}],
  "shapes": {{"ball": {{"type": "sphere", "radius": 0.9}}}},
  "media": {{"m": {{"sigma_a": {}, "sigma_s": {{"texture": {{"type": "noise", "frequency": 3}},
                                              "from": 0.5, "to": [8, 6, 4]}}}}}},
  "objects": [{{"shape": "ball", "medium": "m", "surface": {{"type": "none"}}}}]}})",
                                   tracking, sigma_a));
  };
  auto sky = [](int) { return Rgb(1.0); };
  for (const char* tracking : {"delta", "spectral-history", "spectral-mis"}) {
    SCOPED_TRACE(tracking);
    const RenderResult r = furnace(tracking, 0);
    const test::Chi2 chi2 = test::film_chi2(r.film, sky);
    EXPECT_TRUE(chi2.passes()) << "chi2 " << chi2.value << " over " << chi2.dof;
    EXPECT_EQ(r.counters.tracking.raised, 0u);
    EXPECT_EQ(r.counters.tracking.clamped, 0u);
    // Power: a medium that absorbs (sigma_a 0.3) fails.
    EXPECT_FALSE(test::film_chi2(furnace(tracking, 0.3).film, sky).passes());
  }
}

// The same furnace in spectral mode, sigma_s a spectrum at each end that the texture blends, its
// ends crossing over the visible range: the image is the sky's alone, rendered apart (image
// means within 4 standard errors of their difference in every channel; 4 sampled wavelengths
// leave the sky itself a colour noise of about 1 %), and the octree's bins and the channels'
// majorant factors bound the blend: no majorant is raised. A medium that absorbs (sigma_a 0.3)
// fails the same comparison.
TEST(TextureRender, TexturedChromaticMediumIsInvisibleInASpectralFurnace) {
  auto scene = [](const char* tracking, const char* object, double sigma_a) {
    return fmt::format(R"({{"film": {{"width": 16, "height": 16}},
  "camera": {{"type": "orthographic", "from": [0, 0, 5], "to": [0, 0, 0], "width": 2}},
  "integrator": {{"spp": 32, "seed": 6, "tracking": "{}", "max_depth": 100000}},
  "spectrum": {{"mode": "spectral", "wavelengths": 4}},
  "lights": [{{"type": "environment", "radiance": 1}}],
  "shapes": {{"ball": {{"type": "sphere", "radius": 0.9}}}},
  "media": {{"m": {{"sigma_a": {}, "sigma_s": {{
      "texture": {{"type": "veins", "frequency": 1.5, "sharpness": 2}},
      "from": {{"spectrum": [[400, 1], [700, 6]]}}, "to": {{"spectrum": [[400, 9], [700, 0.5]]}}}}}}}},
  "objects": [{}]}})",
                       tracking, sigma_a, object);
  };
  const char* ball = R"({"shape": "ball", "medium": "m", "surface": {"type": "none"}})";
  // Whether two renders' image means agree within 4 standard errors in every channel.
  auto agree = [](const RenderResult& a, const RenderResult& b) {
    const MeanEstimate ma = image_mean(a.film), mb = image_mean(b.film);
    bool same = true;
    for (int c = 0; c < 3; ++c)
      same = same && std::abs(ma.mean[c] - mb.mean[c]) <=
                         4 * std::hypot(ma.standard_error[c], mb.standard_error[c]);
    return same;
  };
  for (const char* tracking : {"spectral-history", "spectral-mis"}) {
    SCOPED_TRACE(tracking);
    const RenderResult sky = render_text(scene(tracking, "", 0));
    const RenderResult r = render_text(scene(tracking, ball, 0));
    EXPECT_TRUE(agree(r, sky));
    EXPECT_FALSE(agree(render_text(scene(tracking, ball, 0.3)), sky));
    EXPECT_EQ(r.counters.tracking.raised, 0u);
    EXPECT_EQ(r.counters.tracking.clamped, 0u);
  }
}

// A texture's grid file that is missing or is no VDB file is one line naming the key at fault
// and the file, as a density's is.
TEST(TextureLoad, AMissingOrDamagedGridIsOneLineNamingIt) {
  const std::filesystem::path dir = test::fresh_test_dir("texture_grid");
  std::ofstream(dir / "text.vdb") << "not a grid";
  for (const char* file : {"missing.vdb", "text.vdb"}) {
    std::ofstream(dir / "scene.json") << fmt::format(
        R"({{"camera": {{"from": [0, 0, 5], "to": [0, 0, 0]}},
  "shapes": {{"ball": {{"type": "sphere", "radius": 1}}}},
  "objects": [{{"shape": "ball", "surface": {{"albedo": {{
      "texture": {{"type": "vdb", "file": "{}"}}, "from": 0.1, "to": 0.9}}}}}}]}})",
        file);
    std::string error = "(no error)";
    try {
      compile_scene(load_scene_file((dir / "scene.json").string()));
    } catch (const SceneError& e) {
      error = e.what();
    }
    const std::string at = (dir / "scene.json").string() +
                           ": /objects/0/surface/albedo/texture/file: " + (dir / file).string();
    EXPECT_EQ(error, at + (file == std::string("text.vdb")
                               ? ": not a VDB file (it starts with neither OpenVDB's nor "
                                 "NanoVDB's magic number)"
                               : ": cannot open file (No such file or directory)"));
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace nimbus
