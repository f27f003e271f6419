// AOVs (render/aov.h): albedo, normal and depth of what camera paths meet first, against
// analytic scenes (exactly where every sample sees the same thing, within the binomial or
// exponential standard error where a path's choice decides); the variance layer; colour that
// does not change by a bit when AOVs are recorded; layers that are the same bits for any split
// of the work; films, patches and EXRs that carry them; the command line's --aov.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "nimbus/frep/primitives.h"
#include "nimbus/io/exr.h"
#include "nimbus/io/film_file.h"
#include "nimbus/io/film_image.h"
#include "nimbus/job/film_patch.h"
#include "nimbus/render/renderer.h"
#include "nimbus/render/setting_names.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "support/process.h"
#include "support/scene_builders.h"

namespace nimbus {
namespace aov_test {

namespace fs = std::filesystem;
using test::object_of;

const AovSet kRecorded = {Aov::Albedo, Aov::Normal, Aov::Depth};
const AovSet kAll = {Aov::Albedo, Aov::Normal, Aov::Depth, Aov::Variance};

// An orthographic view down -z from z = 4 over [-w/2, w/2]², under a white sky, recording the
// AOVs.
Scene view_down_z(int size, int spp, double view_width) {
  Scene scene;
  scene.settings.width = scene.settings.height = size;
  scene.settings.spp = spp;
  scene.settings.seed = 5;
  scene.settings.aovs = kAll;
  scene.camera = orthographic_camera({0, 0, 4}, {0, 0, 0}, {0, 1, 0}, view_width, size, size);
  scene.lights.push_back(test::environment(1.0));
  return scene;
}

SceneObject diffuse(const ShapePtr& shape, const Rgb& albedo) {
  SceneObject obj = object_of(shape, Surface::Type::Diffuse, -1);
  obj.surface.albedo = albedo;
  return obj;
}

// The index of pixel (x, y).
int pixel_at(const Scene& s, int x, int y) {
  return y * s.settings.width + x;
}

TEST(AovRecord, DiffuseBoxFillingTheViewGivesItsReflectanceNormalAndDistance) {
  Scene scene = view_down_z(8, 4, 2);
  const Rgb albedo({0.7, 0.5, 0.3});
  scene.objects.push_back(diffuse(box({-3, -3, -1}, {3, 3, 1}), albedo));
  finish_scene(scene);
  const Film film = render(scene).film;
  const Image image = to_image(film, kAll);
  ASSERT_EQ(image.layers.size(), 4u);
  for (int p = 0; p < film.pixels(); ++p) {
    // Every sample sees the same face: 4 samples (a power of 2) average to it exactly.
    EXPECT_EQ(film.aov.albedo_mean(p, film.samples[p]), albedo) << p;
    const Vec3 n = film.aov.normal_mean(p, film.samples[p]);
    EXPECT_NEAR(n.x, 0, 1e-15);
    EXPECT_NEAR(n.y, 0, 1e-15);
    EXPECT_NEAR(n.z, 1, 1e-15);
    // The face at z = 1, 3 from the camera's plane: a root of a linear function, to rounding.
    EXPECT_NEAR(film.aov.depth_mean(p), 3.0, 1e-13) << p;
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(image.layers[0].values[3 * size_t(p) + c], float(albedo[c]));
  }
  EXPECT_EQ(image.layers[0].name, "albedo");
  EXPECT_EQ(image.layers[1].channels, (std::vector<std::string>{"X", "Y", "Z"}));
  EXPECT_EQ(image.layers[2].channels, std::vector<std::string>{"Z"});
}

// A unit sphere seen in perspective from 5 away: the centre pixel's mean normal lies within the
// cone of the normals where its footprint's corners meet the sphere (a mean of unit vectors in a
// cone points into it and is at least as long as the cone's cosine).
TEST(AovRecord, SphereNormalAtTheCentrePixelPointsToTheCamera) {
  Scene scene;
  scene.settings = {9, 9, 16, 3, 1000, {}, {}};
  scene.settings.aovs = kRecorded;
  scene.camera = perspective_camera({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 20, 9, 9);
  scene.lights.push_back(test::environment(1.0));
  scene.objects.push_back(diffuse(make_shape(QuadricNode{sphere({0, 0, 0}, 1)}), Rgb(0.5)));
  finish_scene(scene);
  const Film film = render(scene).film;
  double cos_cone = 1;
  for (const auto& [x, y] : {std::pair{4.0, 4.0}, {5.0, 4.0}, {4.0, 5.0}, {5.0, 5.0}}) {
    const Ray r = scene.camera.generate(x, y);
    // |o + t d|² = 1 with |d| = 1: the nearer root.
    const double b = dot(r.o, r.d), t = -b - std::sqrt(b * b - dot(r.o, r.o) + 1);
    cos_cone = std::min(cos_cone, r.at(t).z);
  }
  ASSERT_GT(cos_cone, 0.95);
  const int centre = pixel_at(scene, 4, 4);
  const Vec3 n = film.aov.normal_mean(centre, film.samples[centre]);
  EXPECT_GE(length(n), cos_cone);
  EXPECT_LE(length(n), 1 + 1e-15);
  EXPECT_GE(normalize(n).z, cos_cone);
  EXPECT_LT(cos_cone, 1 - 1e-6) << "the cone must be wider than rounding for the check to bite";
}

// What is not a reflecting surface has albedo 0: the sky (normal 0, no depth), an emissive
// surface and a sphere light (their normals facing the camera).
TEST(AovRecord, MissesEmittersAndLightsHaveAlbedoZero) {
  Scene scene = view_down_z(12, 4, 6);
  SceneObject lamp = object_of(box({-2.6, -0.6, -1}, {-1.4, 0.6, 0}), Surface::Type::Emissive, -1);
  lamp.surface.radiance = Rgb(2.0);
  scene.objects.push_back(lamp);
  Light bulb;
  bulb.type = Light::Type::Sphere;
  bulb.center = {1.75, 0.25, 0};
  bulb.radius = 0.8;
  bulb.emission = Rgb(3.0);
  scene.lights.push_back(bulb);
  finish_scene(scene);
  const Film film = render(scene).film;
  const auto expect_albedo_zero = [&](int p) {
    EXPECT_EQ(film.aov.albedo_mean(p, film.samples[p]), Rgb(0.0)) << p;
  };
  const int sky = pixel_at(scene, 0, 0);
  expect_albedo_zero(sky);
  EXPECT_EQ(film.aov.normal_mean(sky, film.samples[sky]), Vec3{});
  EXPECT_EQ(film.aov.depth_mean(sky), kInf);
  EXPECT_EQ(film.aov.depth_samples[sky], 0u);
  const int on_lamp = pixel_at(scene, 2, 6);  // x in [-2, -1.5], y in [-0.5, 0]: inside
  expect_albedo_zero(on_lamp);
  EXPECT_EQ(film.aov.normal_mean(on_lamp, film.samples[on_lamp]), (Vec3{0, 0, 1}));
  EXPECT_NEAR(film.aov.depth_mean(on_lamp), 4.0, 1e-13);
  const int on_bulb = pixel_at(scene, 9, 5);  // x in [1.5, 2], y in [0, 0.5]: about its centre
  expect_albedo_zero(on_bulb);
  const Vec3 n = film.aov.normal_mean(on_bulb, film.samples[on_bulb]);
  // Rays within r of the centre meet it where the normal's z >= sqrt(R² - r²) / R.
  const double r = std::hypot(0.25, 0.25), z_min = std::sqrt(0.64 - r * r) / 0.8;
  EXPECT_GE(n.z, z_min);
  EXPECT_GE(film.aov.depth_mean(on_bulb), 4 - 0.8);
  EXPECT_LE(film.aov.depth_mean(on_bulb), 4 - std::sqrt(0.64 - r * r));
}

// A lossless glass slab (index 1.5) over a diffuse backdrop, seen at normal incidence: the path
// follows the glass to the backdrop with the probability that light crosses the slab, reflected
// back and forth inside, T = (1 - R) / (1 + R) with R = 0.04, and escapes otherwise. The albedo
// is T times the backdrop's, the normal T times its normal; depth is the glass's.
TEST(AovRecord, GlassSlabAlbedoIsTheSlabsTransmittanceTimesTheBackdrops) {
  Scene scene = view_down_z(8, 64, 2);
  scene.settings.sampler = RenderSettings::Sampler::Independent;
  scene.objects.push_back(object_of(box({-3, -3, 0}, {3, 3, 1}), Surface::Type::Dielectric, -1));
  const Rgb backdrop({0.6, 0.4, 0.2});
  scene.objects.push_back(diffuse(box({-3, -3, -3}, {3, 3, -2}), backdrop));
  finish_scene(scene);
  const Film film = render(scene).film;
  const double R = 0.04, T = (1 - R) / (1 + R);
  double crossed = 0, normal_z = 0;
  for (int p = 0; p < film.pixels(); ++p) {
    crossed += film.aov.albedo_mean(p, film.samples[p])[0] / backdrop[0];
    normal_z += film.aov.normal_mean(p, film.samples[p]).z;
    EXPECT_NEAR(film.aov.depth_mean(p), 3.0, 1e-13);
    const Rgb a = film.aov.albedo_mean(p, film.samples[p]);
    EXPECT_NEAR(a[1] / backdrop[1], a[0] / backdrop[0], 1e-12) << "one choice for all channels";
  }
  crossed /= film.pixels();
  normal_z /= film.pixels();
  // Each sample crosses or not: a Bernoulli(T) mean over independent samples.
  const double n = double(film.pixels()) * scene.settings.spp;
  const double se = std::sqrt(T * (1 - T) / n);
  EXPECT_NEAR(crossed, T, 4 * se);
  EXPECT_NEAR(normal_z, T, 4 * se);
  // Power: one interface's transmittance (no reflections inside) is 8 standard errors away.
  EXPECT_GT(std::abs((1 - R) - T), 8 * se);
}

// A medium of grey extinction 20 filling a thick box (no sample crosses it: e^-40) that
// scatters (1, 2, 3) / 4 of it: the single-scattering albedo at the first collision, the same
// in rgb and spectral mode; normal -ray.d.
TEST(AovRecord, MediumAlbedoIsTheSingleScatteringAlbedoInEitherMode) {
  for (const auto mode : {SpectralSettings::Mode::Rgb, SpectralSettings::Mode::Spectral}) {
    Scene scene = view_down_z(6, 4, 2);
    scene.settings.spectral.mode = mode;
    Medium m;
    m.sigma_s = Rgb({5.0, 10.0, 15.0});
    m.sigma_a = Rgb({15.0, 10.0, 5.0});
    scene.media.push_back(m);
    scene.objects.push_back(object_of(box({-3, -3, -1}, {3, 3, 1}), Surface::Type::None, 0));
    finish_scene(scene);
    const Film film = render(scene).film;
    for (int p = 0; p < film.pixels(); ++p) {
      EXPECT_EQ(film.aov.albedo_mean(p, film.samples[p]), Rgb({0.25, 0.5, 0.75})) << p;
      EXPECT_EQ(film.aov.normal_mean(p, film.samples[p]), (Vec3{0, 0, 1}));
      EXPECT_GT(film.aov.depth_mean(p), 3.0);
    }
  }
}

// Depth in a medium is the distance to the first real collision: past the box's face at 3,
// exponential of rate mu = 20 in every tracking mode for a grey medium that only scatters, so
// its mean over independent samples is 3 + 1/mu (less 2e^-40 for the box's far side) within the
// exponential's standard error.
class AovMediumDepth : public ::testing::TestWithParam<TrackingSettings::Mode> {};

TEST_P(AovMediumDepth, IsTheMeanFreePathPastTheBoundary) {
  Scene scene = view_down_z(16, 16, 2);
  scene.settings.sampler = RenderSettings::Sampler::Independent;
  scene.settings.tracking.mode = GetParam();
  const double mu = 20;
  Medium m;
  m.sigma_s = Rgb(mu);
  scene.media.push_back(m);
  scene.objects.push_back(object_of(box({-3, -3, -1}, {3, 3, 1}), Surface::Type::None, 0));
  finish_scene(scene);
  const Film film = render(scene).film;
  double mean = 0;
  for (int p = 0; p < film.pixels(); ++p) {
    ASSERT_EQ(film.aov.depth_samples[p], uint32_t(scene.settings.spp));
    mean += film.aov.depth_mean(p);
  }
  mean /= film.pixels();
  const double se = (1 / mu) / std::sqrt(double(film.pixels()) * scene.settings.spp);
  EXPECT_NEAR(mean, 3 + 1 / mu, 4 * se);
  EXPECT_GT(1 / mu, 8 * se) << "power: the medium's face alone (depth 3) would fail";
}

INSTANTIATE_TEST_SUITE_P(Modes, AovMediumDepth,
                         ::testing::Values(TrackingSettings::Mode::Delta,
                                           TrackingSettings::Mode::SpectralMax,
                                           TrackingSettings::Mode::SpectralHistory,
                                           TrackingSettings::Mode::SpectralMis),
                         [](const auto& info) {
                           std::string name(name_of(kTrackingModeNames, info.param));
                           std::erase(name, '-');
                           return name;
                         });

// A shipped scene, small, with the AOVs given.
Scene shipped(const std::string& name, AovSet aovs, int spp = 2) {
  SceneDesc desc = load_scene_file(std::string(NIMBUS_SOURCE_DIR) + "/scenes/" + name + ".json",
                                   {"film.width=24", "film.height=16"});
  desc.settings.spp = spp;
  desc.settings.aovs = aovs;
  return compile_scene(desc);
}

// The AOV sums of two films are the same bits.
void expect_same_aov_bits(const Film& a, const Film& b) {
  ASSERT_EQ(a.aov.layers, b.aov.layers);
  EXPECT_TRUE(a.aov.albedo == b.aov.albedo);
  EXPECT_TRUE(a.aov.normal == b.aov.normal);
  EXPECT_TRUE(a.aov.depth == b.aov.depth);
  EXPECT_TRUE(a.aov.depth_samples == b.aov.depth_samples);
}

TEST(AovFilm, VarianceLayerIsTheFilmsVarianceOfTheMean) {
  const Film film = render(shipped("demo", {Aov::Variance}, 4)).film;
  EXPECT_TRUE(film.aov.layers.empty()) << "variance needs no sums of its own";
  const Image image = to_image(film, {Aov::Variance});
  ASSERT_EQ(image.layers.size(), 1u);
  EXPECT_EQ(image.layers[0].name, "variance");
  double largest = 0;
  for (int p = 0; p < film.pixels(); ++p)
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(image.layers[0].values[3 * size_t(p) + c], float(film.variance_of_mean(p)[c]));
      largest = std::max(largest, film.variance_of_mean(p)[c]);
    }
  EXPECT_GT(largest, 0);
}

// The samples layer is each pixel's count, from the film's counts: no sums of its own.
TEST(AovFilm, SamplesLayerIsEachPixelsCount) {
  Scene scene = shipped("demo", {Aov::Samples}, 4);
  Film film = make_film(scene);
  EXPECT_TRUE(film.aov.layers.empty()) << "samples needs no sums of its own";
  render_into(scene, film, {1, {}, {0, 0, 5, -1, 0, 3}, {}});
  render_into(scene, film, {1, {}, {5, 0, -1, -1, 0, 4}, {}});
  const Image image = to_image(film, {Aov::Samples});
  ASSERT_EQ(image.layers.size(), 1u);
  EXPECT_EQ(image.layers[0].name, "samples");
  EXPECT_EQ(image.layers[0].channels, std::vector<std::string>{"N"});
  for (int p = 0; p < film.pixels(); ++p)
    EXPECT_EQ(image.layers[0].values[size_t(p)], p % film.width < 5 ? 3.0f : 4.0f);
}

// Recording draws no number and traces no ray: the colour's sums, its sums of squares and the
// counters are the bits of a render without AOVs, in scenes with every kind of first vertex
// (diffuse, glass, emitters, media, the sky; rgb and spectral mode).
class AovColour : public ::testing::TestWithParam<const char*> {};

TEST_P(AovColour, RecordingChangesNoBitOfTheColour) {
  const RenderResult plain = render(shipped(GetParam(), {}));
  const RenderResult with = render(shipped(GetParam(), kAll));
  EXPECT_TRUE(plain.film.aov.layers.empty());
  EXPECT_EQ(with.film.aov.layers, kRecorded);
  EXPECT_TRUE(plain.film.sum == with.film.sum);
  EXPECT_TRUE(plain.film.sum_sq == with.film.sum_sq);
  EXPECT_TRUE(plain.film.samples == with.film.samples);
  EXPECT_EQ(plain.counters.surface_rays, with.counters.surface_rays);
  EXPECT_EQ(plain.counters.shadow_rays, with.counters.shadow_rays);
  EXPECT_EQ(plain.counters.tracking.lookups, with.counters.tracking.lookups);
}

INSTANTIATE_TEST_SUITE_P(Scenes, AovColour,
                         ::testing::Values("demo", "translucent", "cloud_sunlit", "spectral"));

// Exact sums: one render, a render on another number of threads, and the samples rendered in
// two parts into two films merged in reverse order give the same bits.
TEST(AovFilm, LayersAreTheSameBitsForAnyThreadsAndSplits) {
  const Scene scene = shipped("translucent", kAll, 4);
  RenderOptions one_thread;
  one_thread.threads = 1;
  const Film once = render(scene, one_thread).film;
  RenderOptions two_threads;
  two_threads.threads = 2;
  expect_same_aov_bits(once, render(scene, two_threads).film);
  Film first = make_film(scene), second = make_film(scene);
  RenderOptions part;
  part.range = {0, 0, -1, -1, 0, 1};
  render_into(scene, first, part);
  part.range = {0, 0, -1, -1, 1, 4};
  render_into(scene, second, part);
  merge(second, first);
  expect_same_aov_bits(once, second);
}

TEST(AovFilm, FilmFilesPatchesAndExrsCarryTheLayers) {
  const Scene scene = shipped("translucent", kAll);
  const Film film = render(scene).film;
  const fs::path dir = test::fresh_test_dir("nimbus_aov");
  save_film(film, (dir / "f.film").string());
  const Film loaded = load_film((dir / "f.film").string());
  expect_same_aov_bits(film, loaded);
  EXPECT_EQ(loaded.aov.depth_exponent, film.aov.depth_exponent);

  Film source = film, rebuilt = make_film(scene);
  const PixelRect rect{3, 2, 17, 11};
  const FilmPatch patch = unpack_patch(pack_patch(take_patch(source, rect)));
  merge_patch(rebuilt, patch);
  merge_patch(rebuilt, take_patch(source, {0, 0, 24, 16}));
  expect_same_aov_bits(film, rebuilt);

  const Image image = to_image(film, kAll);
  write_exr((dir / "a.exr").string(), image);
  const Image read = read_exr((dir / "a.exr").string());
  EXPECT_EQ(read.rgb, image.rgb);
  ASSERT_EQ(read.layers.size(), 4u);
  for (const ImageLayer& written : image.layers) {
    const auto it = std::find_if(read.layers.begin(), read.layers.end(),
                                 [&](const ImageLayer& l) { return l.name == written.name; });
    ASSERT_NE(it, read.layers.end()) << written.name;
    EXPECT_EQ(it->channels, written.channels);
    EXPECT_EQ(it->values, written.values) << written.name;
  }
  fs::remove_all(dir);
}

// The command line: --aov and film.aov, their errors, and a checkpointed render.
constexpr const char* kScene = R"({
  "film": {"width": 12, "height": 8},
  "camera": {"type": "perspective", "from": [0, 1, 6], "to": [0, 0, 0], "fov": 35},
  "integrator": {"spp": 4, "seed": 7},
  "lights": [{"type": "environment", "radiance": [0.8, 0.9, 1.0]}],
  "media": {"fog": {"sigma_a": 0.2, "sigma_s": [3, 4, 5]}},
  "objects": [
    {"shape": {"type": "sphere", "center": [-1, 0, 0], "radius": 0.8}, "medium": "fog"},
    {"shape": {"type": "sphere", "center": [1, 0, 0], "radius": 0.8},
     "surface": {"type": "dielectric", "ior": 1.5}},
    {"shape": {"type": "box", "min": [-5, -1.6, -5], "max": [5, -1.5, 5]},
     "surface": {"type": "diffuse", "albedo": [0.7, 0.5, 0.3]}}
  ]
})";

class AovCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_test_dir("nimbus_aovcli");
    std::ofstream(dir_ / "scene.json") << kScene;
  }
  void TearDown() override { fs::remove_all(dir_); }
  test::Ran run(const std::string& args) { return test::run_nimbus_in(dir_, args); }
  void expect_refused(const std::string& args, const std::string& line) {
    const test::Ran r = run(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(r.err, line + "\n") << args;
    for (const auto& e : fs::directory_iterator(dir_))
      EXPECT_EQ(e.path().filename(), "scene.json") << "nothing written: " << args;
  }
  std::vector<std::string> layer_names(const std::string& exr) {
    std::vector<std::string> names;
    for (const ImageLayer& l : read_exr((dir_ / exr).string()).layers) names.push_back(l.name);
    return names;
  }
  fs::path dir_;
};

TEST_F(AovCli, RefusesUnknownAndRepeatedNamesAndPngOutputs) {
  expect_refused("render scene.json -o a.exr --aov albedo,nromal",
                 "nimbus: --aov: unknown AOV \"nromal\" (one of: albedo, normal, depth, variance, "
                 "samples)");
  expect_refused("render scene.json -o a.exr --aov depth,depth",
                 "nimbus: --aov: names \"depth\" twice");
  expect_refused("render scene.json -o a.exr -o a.png --aov albedo",
                 "nimbus: -o a.png: AOVs (--aov, film.aov) are layers of an EXR; write the render "
                 "to an .exr");
  expect_refused("render scene.json -o a.png --set 'film.aov=[\"normal\"]'",
                 "nimbus: -o a.png: AOVs (--aov, film.aov) are layers of an EXR; write the render "
                 "to an .exr");
  expect_refused("render scene.json -o a.exr --set 'film.aov=[\"albedo\", \"Depth\"]'",
                 "--set film.aov=[\"albedo\", \"Depth\"]: /film/aov/1: unknown AOV \"Depth\" "
                 "(expected one of: albedo, normal, depth, variance, samples)");
}

TEST_F(AovCli, WritesTheLayersIntoTheExrAlone) {
  const test::Ran r = run("render scene.json -q --aov normal,albedo,variance,depth");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "scene.exr"));
  EXPECT_FALSE(fs::exists(dir_ / "scene.png")) << "the default outputs are the EXR alone";
  // OpenEXR lists channels by name.
  EXPECT_EQ(layer_names("scene.exr"),
            (std::vector<std::string>{"albedo", "depth", "normal", "variance"}));
  // --aov overrides the scene's film.aov; without either the EXR holds the colour alone.
  ASSERT_EQ(run("render scene.json -q -o b.exr --set 'film.aov=[\"depth\"]' --aov albedo").code, 0);
  EXPECT_EQ(layer_names("b.exr"), std::vector<std::string>{"albedo"});
  ASSERT_EQ(run("render scene.json -q -o c.exr").code, 0);
  EXPECT_TRUE(layer_names("c.exr").empty());
  EXPECT_EQ(read_exr((dir_ / "c.exr").string()).rgb, read_exr((dir_ / "scene.exr").string()).rgb);
}

// A render checkpointed at 2 spp and resumed to 4 writes the colour and the albedo, normal and
// depth of one render of 4 spp to the bit (the variance to rounding: its sums of squares are
// added per work unit); a checkpoint without the AOVs is not resumed with them.
TEST_F(AovCli, CheckpointedAndResumedRendersWriteTheLayersOfOneRender) {
  ASSERT_EQ(run("render scene.json -q -o once.exr --aov albedo,normal,depth,variance").code, 0);
  ASSERT_EQ(run("render scene.json -q -o part.exr --spp 2 --checkpoint ck.nck --aov "
                "albedo,normal,depth,variance")
                .code,
            0);
  const test::Ran resumed =
      run("render scene.json -q -o resumed.exr --resume ck.nck --spp 4 --aov "
          "albedo,normal,depth,variance");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  const Image once = read_exr((dir_ / "once.exr").string());
  const Image again = read_exr((dir_ / "resumed.exr").string());
  EXPECT_EQ(once.rgb, again.rgb);
  ASSERT_EQ(once.layers.size(), 4u);
  ASSERT_EQ(again.layers.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    ASSERT_EQ(once.layers[i].name, again.layers[i].name);
    if (once.layers[i].name != "variance") {
      EXPECT_EQ(once.layers[i].values, again.layers[i].values) << once.layers[i].name;
      continue;
    }
    for (size_t k = 0; k < once.layers[i].values.size(); ++k)
      EXPECT_NEAR(again.layers[i].values[k], once.layers[i].values[k],
                  1e-5 * once.layers[i].values[k]);
  }
  const test::Ran other = run("render scene.json -q -o other.exr --resume ck.nck --spp 4");
  EXPECT_EQ(other.code, 2);
  EXPECT_NE(other.err.find("the checkpoint is of another scene or other settings"),
            std::string::npos)
      << other.err;
}

}  // namespace aov_test
}  // namespace nimbus
