// Emission from a temperature grid (media/temperature_emission.h, issue 14), with grids written
// in the test with OpenVDB's own API and scenes loaded from files: a constant temperature in a
// pure absorber renders as the {"blackbody": K} colour of the same radiance (the same paths, so
// to the table's rounding) and as the closed form L = L_e (1 − T) + T L_env; a temperature
// gradient renders the quadrature of Planck's emission along the ray, and not that of the
// gradient reversed; in rgb and in spectral mode. Every bad input is one line naming the JSON
// path and the file, and the command line exits 2 without output.

#include "nimbus/media/temperature_emission.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "nimbus/math/constants.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "nimbus/spectral/color.h"
#include "nimbus/spectral/planck.h"
#include "support/film_chi2.h"
#include "support/vdb_grids.h"

namespace nimbus {
namespace temperature_emission_test {

using test::TempDir;

constexpr double kVoxel = 0.1;

// A float grid named `name` whose voxels (i, j, k) in [lo, hi] are active and hold value(i, j,
// k); voxel size kVoxel, index (0, 0, 0) at the world origin.
test::FloatGrid grid_of(const std::string& name, const test::Coord& lo, const test::Coord& hi,
                        const std::function<double(int, int, int)>& value) {
  test::FloatGrid g{.name = name, .voxel = kVoxel};
  for (int i = lo.i; i <= hi.i; ++i)
    for (int j = lo.j; j <= hi.j; ++j)
      for (int k = lo.k; k <= hi.k; ++k)
        g.voxels.push_back({{i, j, k}, static_cast<float>(value(i, j, k))});
  return g;
}

// The luminance of Planck's radiance at T, computed here rather than from planck.h's table.
double luminance_of_planck(double kelvin) {
  return linear_srgb_to_xyz(emission_to_rgb(planck_spectrum(kelvin))).y;
}

// An absorber filling `box` (JSON), emitting `emission` (JSON), before an environment of
// radiance `env`, seen by an 8 × 8 orthographic camera; `mode` "rgb" or "spectral".
std::string absorber_scene(const std::string& mode, const std::string& camera, double sigma_a,
                           const std::string& box, const std::string& emission, double env,
                           int spp) {
  return fmt::format(R"({{
    "film": {{"width": 8, "height": 8}},
    "camera": {camera},
    "integrator": {{"spp": {spp}, "seed": 9, "sampler": "independent"}},
    "spectrum": {{"mode": "{mode}", "wavelengths": 4}},
    "lights": [{{"type": "environment", "radiance": {env}}}],
    "media": {{"fire": {{"sigma_a": {sigma_a}, "emission": {emission}}}}},
    "objects": [{{"shape": {box}, "medium": "fire"}}]
  }})",
                     fmt::arg("camera", camera), fmt::arg("spp", spp), fmt::arg("mode", mode),
                     fmt::arg("env", env), fmt::arg("sigma_a", sigma_a), fmt::arg("box", box),
                     fmt::arg("emission", emission));
}

RenderResult render_file(const TempDir& dir, const std::string& name, const std::string& text,
                         Scene* compiled = nullptr) {
  std::ofstream(dir.file(name)) << text;
  Scene scene = compile_scene(load_scene_file(dir.file(name)));
  RenderOptions options;
  options.threads = 2;
  RenderResult r = render(scene, options);
  EXPECT_EQ(r.counters.rejected_samples, 0u);
  if (compiled) *compiled = std::move(scene);
  return r;
}

// The environment's radiance `env` as the film sees it: itself in rgb mode, its D65-shaped
// curve's projection in spectral mode.
Rgb environment_rgb(const std::string& mode, double env) {
  return mode == "rgb" ? Rgb(env) : emission_to_rgb(rgb_illuminant_spectrum(Rgb(env)));
}

// The film's expected sRGB of Planck's radiance at T: in rgb mode the clamped projection that
// the renderer emits (planck_rgb), in spectral mode the projection of the spectrum itself, which
// may be negative outside the gamut.
Rgb film_rgb_of_planck(const std::string& mode, double kelvin) {
  return mode == "rgb" ? planck_rgb(kelvin) : emission_to_rgb(planck_spectrum(kelvin));
}

// The largest standard error of a pixel-channel.
double largest_standard_error(const Film& film) {
  double se = 0;
  for (int p = 0; p < film.pixels(); ++p)
    se = std::max(se, std::sqrt(film.variance_of_mean(p).max()));
  return se;
}

class TemperatureGrid : public testing::TestWithParam<std::string> {};

// A unit box of absorber (σ_a = 1) inside a grid at 1800 K, seen along z: every pixel is
// L = s B(1800) (1 − e⁻¹) + e⁻¹ L_env. The constant colour {"blackbody": 1800, "scale": s Y}
// (Y: B's luminance) is the same radiance, and the absorber's paths do not depend on emission,
// so the same seed renders it to the table's rounding.
TEST_P(TemperatureGrid, ConstantTemperatureRendersAsTheBlackbodyColour) {
  const std::string mode = GetParam();
  const TempDir dir("temperature_constant");
  constexpr double kKelvin = 1800, kEnv = 0.5;
  test::write_vdb(dir.file("fire.vdb"), {grid_of("temperature", {-3, -3, -3}, {13, 13, 13},
                                                 [](int, int, int) { return kKelvin; })});
  const double s = 2 / luminance_of_planck(kKelvin);  // luminance 2
  const std::string camera =
      R"({"type": "orthographic", "from": [0.5, 0.5, 3], "to": [0.5, 0.5, 0], "width": 0.8})";
  const std::string box = R"({"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]})";
  Scene scene;
  const RenderResult grid = render_file(
      dir, "grid.json",
      absorber_scene(mode, camera, 1, box,
                     fmt::format(R"({{"file": "fire.vdb", "scale": {:.17g}}})", s), kEnv, 512),
      &scene);
  const RenderResult colour =
      render_file(dir, "colour.json",
                  absorber_scene(mode, camera, 1, box,
                                 fmt::format(R"({{"blackbody": {}, "scale": {:.17g}}})", kKelvin,
                                             s * luminance_of_planck(kKelvin)),
                                 kEnv, 512));

  // The grid's emission at points: Planck's radiance inside, none beyond the active voxels.
  ASSERT_TRUE(scene.media[0].emission_grid);
  const TemperatureEmission& e = *scene.media[0].emission_grid;
  const Rgb Le = planck_rgb(kKelvin) * s;
  const std::array<double, 3> unused{};
  EXPECT_LT((temperature_emission_at<3>(e, {0.5, 0.5, 0.5}, false, unused) - Le).max_abs(), 1e-12);
  EXPECT_EQ(temperature_emission_at<3>(e, {2, 0.5, 0.5}, false, unused).max_abs(), 0.0);
  const std::array<double, 4> lambda{400, 500, 600, 700};
  const Spectrum<4> spectral = temperature_emission_at<4>(e, {0.5, 0.5, 0.5}, true, lambda);
  for (int i = 0; i < 4; ++i)
    EXPECT_NEAR(spectral[i] / (s * planck_radiance(lambda[i], kKelvin)), 1, 1e-12);

  // The same paths: pixel by pixel, equal to the table's relative 1e-6.
  for (int p = 0; p < grid.film.pixels(); ++p)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(grid.film.mean(p)[c], colour.film.mean(p)[c], 1e-6 * Le.max_abs())
          << "pixel " << p << " channel " << c;

  // Against the closed form, per pixel (chi-square of the render's own variance), and a power
  // check: 100 K hotter must fail it.
  const double T = std::exp(-1.0);
  const Rgb env = environment_rgb(mode, kEnv);
  const auto closed_form = [&](double kelvin) {
    const Rgb L = film_rgb_of_planck(mode, kelvin) * s * (1 - T) + env * T;
    return [L](int) { return L; };
  };
  const test::Chi2 right = test::film_chi2(grid.film, closed_form(kKelvin));
  const test::Chi2 hotter = test::film_chi2(grid.film, closed_form(kKelvin + 100));
  EXPECT_EQ(right.dof, 8 * 8 * 3);
  EXPECT_TRUE(right.passes()) << right.value << " for " << right.dof;
  EXPECT_FALSE(hotter.passes()) << hotter.value << " for " << hotter.dof;
  EXPECT_LT(largest_standard_error(grid.film), 0.25);  // measured: 0.110 (rgb), 0.118 (spectral)
}

// A slab 2 long in x of absorber (σ_a = 0.25, τ = 0.5) in a grid whose temperature rises
// linearly from 1000 K at x = 0 to 3000 K at x = 2 (trilinear interpolation reproduces it
// exactly), seen along −x: every pixel is ∫₀² σ_a e^{−σ_a t} s B(T(2 − t)) dt + e^{−τ} L_env, by
// Simpson's rule with B's sRGB from the integration (not planck_rgb's table). The emission rises
// 10⁴-fold along the ray, so the same slab seen from the cold end (the gradient reversed) fails.
TEST_P(TemperatureGrid, GradientMatchesQuadratureAlongTheRay) {
  const std::string mode = GetParam();
  const TempDir dir("temperature_gradient");
  constexpr double kSigmaA = 0.25, kLength = 2, kEnv = 0.2;
  const auto kelvin_at = [](double x) { return 1000 + 1000 * x; };
  test::write_vdb(dir.file("fire.vdb"),
                  {grid_of("heat", {-3, -3, -3}, {23, 13, 13},
                           [&](int i, int, int) { return kelvin_at(i * kVoxel); })});
  const double s = 1 / luminance_of_planck(3000);
  const RenderResult r = render_file(
      dir, "gradient.json",
      absorber_scene(
          mode,
          R"({"type": "orthographic", "from": [4, 0.5, 0.5], "to": [0, 0.5, 0.5], "width": 0.8})",
          kSigmaA, R"({"type": "box", "min": [0, 0, 0], "max": [2, 1, 1]})",
          fmt::format(R"({{"file": "fire.vdb", "grid": "heat", "scale": {:.17g}}})", s), kEnv,
          1024));
  const auto quadrature = [&](const std::function<double(double)>& kelvin_at_depth) {
    constexpr int kSteps = 2000;  // even; Simpson's error is far below the render's
    const double h = kLength / kSteps;
    Rgb sum(0.0);
    for (int k = 0; k <= kSteps; ++k) {
      const double t = k * h, w = k == 0 || k == kSteps ? 1 : k % 2 ? 4 : 2;
      // rgb mode clamps each point's emission, so the reference does too.
      Rgb Le = emission_to_rgb(planck_spectrum(kelvin_at_depth(t)));
      if (mode == "rgb")
        for (int c = 0; c < 3; ++c) Le[c] = std::max(Le[c], 0.0);
      sum += Le * (w * kSigmaA * std::exp(-kSigmaA * t));
    }
    const Rgb L = sum * (s * h / 3) + environment_rgb(mode, kEnv) * std::exp(-kSigmaA * kLength);
    return [L](int) { return L; };
  };
  const test::Chi2 right =
      test::film_chi2(r.film, quadrature([&](double t) { return kelvin_at(kLength - t); }));
  const test::Chi2 reversed =
      test::film_chi2(r.film, quadrature([&](double t) { return kelvin_at(t); }));
  EXPECT_EQ(right.dof, 8 * 8 * 3);
  EXPECT_TRUE(right.passes()) << right.value << " for " << right.dof;
  EXPECT_FALSE(reversed.passes()) << reversed.value << " for " << reversed.dof;
  EXPECT_LT(largest_standard_error(r.film), 0.05);
}

// Emission per unit length (Cycles' convention) under the Stefan–Boltzmann law, in a slab that
// neither absorbs nor scatters: its grid holds T / 1000 and "temperature_scale" 1000 makes it T,
// rising linearly from 1000 K at x = 0 to 3000 K at x = 2, and a cloud density that is 0 in
// places, which emission per unit length ignores. Seen along −x every pixel is
// ∫₀² j(T(x)) dx + L_env with j(T) = s σ T⁴/π · B(·, T)/Y(T), by Simpson's rule. Nothing
// collides there, so the emission is all the track-length estimator's (render/glow.h). A
// gradient 2 % hotter fails. A constant 1800 K grid renders as the {"blackbody": 1800} colour of
// luminance s σ 1800⁴/π per unit length, to the table's rounding.
TEST_P(TemperatureGrid, PerLengthStefanBoltzmannMatchesQuadrature) {
  const std::string mode = GetParam();
  const TempDir dir("temperature_per_length");
  constexpr double kLength = 2, kEnv = 0.2, kScale = 1e-6;
  const auto kelvin_at = [](double x) { return 1000 + 1000 * x; };
  test::write_vdb(dir.file("fire.vdb"),
                  {grid_of("heat", {-3, -3, -3}, {23, 13, 13},
                           [&](int i, int, int) { return kelvin_at(i * kVoxel) / 1000; }),
                   grid_of("hot", {-3, -3, -3}, {23, 13, 13}, [](int, int, int) { return 1.8; })});
  const auto scene_text = [&](const std::string& j) {
    return fmt::format(R"({{
      "film": {{"width": 8, "height": 8}},
      "camera": {{"type": "orthographic", "from": [4, 0.5, 0.5], "to": [0, 0.5, 0.5],
                  "width": 0.8}},
      "integrator": {{"spp": 1024, "seed": 9, "sampler": "independent"}},
      "spectrum": {{"mode": "{}", "wavelengths": 4}},
      "lights": [{{"type": "environment", "radiance": {}}}],
      "media": {{"fire": {{"sigma_s": 0, "density": {{"type": "cloud"}},
                          "emission_per_length": {}}}}},
      "objects": [{{"shape": {{"type": "box", "min": [0, 0, 0], "max": [2, 1, 1]}},
                   "medium": "fire"}}]
    }})",
                       mode, kEnv, j);
  };
  const auto grid_j = [&](const std::string& grid) {
    return fmt::format(R"({{"file": "fire.vdb", "grid": "{}", "law": "stefan-boltzmann",
                           "scale": {}, "temperature_scale": 1000}})",
                       grid, kScale);
  };
  Scene scene;
  const RenderResult r = render_file(dir, "gradient.json", scene_text(grid_j("heat")), &scene);
  ASSERT_EQ(scene.glowing_objects.size(), 1u);
  const auto j_of = [&](double kelvin) {
    Rgb B = emission_to_rgb(planck_spectrum(kelvin));
    if (mode == "rgb")  // rgb mode clamps each point's emission, so the reference does too
      for (int c = 0; c < 3; ++c) B[c] = std::max(B[c], 0.0);
    return B *
           (kScale * kStefanBoltzmann * std::pow(kelvin, 4) / kPi / luminance_of_planck(kelvin));
  };
  const auto quadrature = [&](const std::function<double(double)>& kelvin_at_depth) {
    constexpr int kSteps = 2000;
    const double h = kLength / kSteps;
    Rgb sum(0.0);
    for (int k = 0; k <= kSteps; ++k) {
      const double w = k == 0 || k == kSteps ? 1 : k % 2 ? 4 : 2;
      sum += j_of(kelvin_at_depth(k * h)) * w;
    }
    const Rgb L = sum * (h / 3) + environment_rgb(mode, kEnv);
    return [L](int) { return L; };
  };
  const test::Chi2 right =
      test::film_chi2(r.film, quadrature([&](double t) { return kelvin_at(kLength - t); }));
  const test::Chi2 hotter =
      test::film_chi2(r.film, quadrature([&](double t) { return 1.02 * kelvin_at(kLength - t); }));
  EXPECT_EQ(right.dof, 8 * 8 * 3);
  EXPECT_TRUE(right.passes()) << right.value << " for " << right.dof;
  EXPECT_FALSE(hotter.passes()) << hotter.value << " for " << hotter.dof;

  const RenderResult grid = render_file(dir, "hot.json", scene_text(grid_j("hot")));
  const RenderResult colour =
      render_file(dir, "colour.json",
                  scene_text(fmt::format(R"({{"blackbody": 1800, "scale": {:.17g}}})",
                                         kScale * kStefanBoltzmann * std::pow(1800.0, 4) / kPi)));
  const double largest = j_of(1800).max_abs() * kLength;
  for (int p = 0; p < grid.film.pixels(); ++p)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(grid.film.mean(p)[c], colour.film.mean(p)[c], 1e-6 * largest)
          << "pixel " << p << " channel " << c;
}

INSTANTIATE_TEST_SUITE_P(Modes, TemperatureGrid, testing::Values("rgb", "spectral"),
                         [](const testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

// The error of a scene in `dir` whose medium "m" has the given emission (at `key`).
std::string load_error(const TempDir& dir, const std::string& emission,
                       const std::string& key = "emission") {
  std::ofstream(dir.file("scene.json"))
      << R"({"camera": {"from": [0, 0, 5], "to": [0, 0, 0]}, "media": {"m": {"sigma_a": 1, ")"
      << key << R"(": )" << emission << "}}}";
  try {
    compile_scene(load_scene_file(dir.file("scene.json")));  // the grid is read by compiling
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(TemperatureGridErrors, BadInputIsOneLineNamingTheJsonPathAndTheFile) {
  const TempDir dir("temperature_errors");
  const std::string at = dir.file("scene.json") + ": /media/m/emission";
  test::write_vdb(dir.file("smoke.vdb"),
                  {grid_of("density", {0, 0, 0}, {1, 1, 1}, [](int, int, int) { return 1; }),
                   grid_of("flames", {0, 0, 0}, {1, 1, 1}, [](int, int, int) { return 1; })});
  test::write_vec3s_vdb(dir.file("vectors.vdb"), "temperature", {0, 0, 0}, {1, 0, 0});
  test::write_level_set_sphere_vdb(dir.file("levelset.vdb"), "temperature", 1.0, 0.1);
  std::ofstream(dir.file("text.vdb")) << "hot air\n";
  // Issue 29: a grid at 3e38 K made NaN samples; it emits about 1e40, beyond what a scene may.
  test::write_vdb(dir.file("hot.vdb"), {grid_of("temperature", {0, 0, 0}, {1, 1, 1},
                                                [](int, int, int) { return 3e38; })});

  struct Case {
    std::string emission, expected;
  };
  const Case cases[] = {
      {R"({"file": "nowhere.vdb"})",
       at + "/file: " + dir.file("nowhere.vdb") + ": cannot open file (No such file or directory)"},
      {R"({"file": "text.vdb"})",
       at + "/file: " + dir.file("text.vdb") +
           ": not a VDB file (it starts with neither OpenVDB's nor NanoVDB's magic number)"},
      {R"({"file": "smoke.vdb"})",
       at + ": " + dir.file("smoke.vdb") +
           R"(: grid "temperature" is not in the file (the file holds grids "density", "flames"))"},
      {R"({"file": "smoke.vdb", "grid": "heat"})",
       at + "/grid: " + dir.file("smoke.vdb") +
           R"(: grid "heat" is not in the file (the file holds grids "density", "flames"))"},
      {R"({"file": "vectors.vdb"})",
       at + ": " + dir.file("vectors.vdb") +
           R"(: grid "temperature" holds vec3s values; a temperature grid holds float or double values)"},
      {R"({"file": "levelset.vdb"})",
       at + ": " + dir.file("levelset.vdb") +
           R"(: grid "temperature" is a level set (signed distances), not a temperature; convert it to a fog volume first (OpenVDB's tools::sdfToFogVolume))"},
      {R"({"file": "smoke.vdb", "grid": "flames", "scale": -1})",
       at + "/scale: must be in [0, 1e+30]"},
      {R"({"file": "smoke.vdb", "grid": "flames", "scale": 1e31})",
       at + "/scale: must be in [0, 1e+30]"},
      {R"({"file": "hot.vdb"})",
       at + ": " + dir.file("hot.vdb") +
           R"(: grid "temperature" reaches 3e+38 K, where the emitted radiance (times scale 1) is )" +
           fmt::format("{:.3g}", std::max(planck_rgb(3e38f).max(), planck_spectrum(3e38f).scale)) +
           "; emitted light may be at most 1e+30"},
      {R"({"file": ""})", at + "/file: must name a file"},
      {R"({"file": "hot.vdb\u0000junk"})", at + "/file: a file name cannot hold a NUL byte"},
      {R"({"file": "smoke.vdb", "grid": ""})", at + "/grid: must name a grid"},
      {R"({"grid": "flames"})", at + "/file: required key is missing"},
      {R"({"file": "nowhere.vdb", "sclae": 2})",
       at + R"(/sclae: unknown key for a temperature grid's emission (did you mean "scale"?))"},
      {R"({"file": "smoke.vdb", "grid": "flames", "law": "cycles"})",
       at + R"(/law: unknown law "cycles" (expected one of: planck, stefan-boltzmann))"},
      {R"({"file": "smoke.vdb", "grid": "flames", "temperature_scale": -1})",
       at + "/temperature_scale: must be in [0, 1e+30]"},
  };
  for (const Case& c : cases) {
    const std::string e = load_error(dir, c.emission);
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    EXPECT_EQ(e, c.expected);
  }
  // The same file's other grid, and a colour, load.
  EXPECT_EQ(load_error(dir, R"({"file": "smoke.vdb", "grid": "flames", "scale": 0.5})"),
            "(no error)");
  EXPECT_EQ(load_error(dir, R"({"blackbody": 1500})"), "(no error)");
  // Emission per unit length takes the same grids and colours, with the same checks.
  const std::string per_length = dir.file("scene.json") + ": /media/m/emission_per_length";
  EXPECT_EQ(load_error(dir, R"({"file": "smoke.vdb", "grid": "heat"})", "emission_per_length"),
            per_length + "/grid: " + dir.file("smoke.vdb") +
                R"(: grid "heat" is not in the file (the file holds grids "density", "flames"))");
  EXPECT_EQ(load_error(dir, "-0.5", "emission_per_length"), per_length + ": must be in [0, 1e+30]");
  EXPECT_EQ(load_error(dir, R"({"file": "smoke.vdb", "grid": "flames", "law": "stefan-boltzmann"})",
                       "emission_per_length"),
            "(no error)");
  EXPECT_EQ(load_error(dir, "[0.1, 0.2, 0.3]", "emission_per_length"), "(no error)");
}

// As a program: a scene whose temperature grid is missing exits 2 with that one line and writes
// no image.
TEST(TemperatureGridErrors, TheCommandLineExitsTwoWithoutOutput) {
  const TempDir dir("temperature_cli");
  std::ofstream(dir.file("scene.json"))
      << absorber_scene("rgb", R"({"from": [0, 0, 5], "to": [0, 0, 0]})", 1,
                        R"({"type": "sphere", "radius": 1})", R"({"file": "fire.vdb"})", 0, 1);
  const std::string cmd = "cd '" + dir.path().string() +
                          "' && '" NIMBUS_BINARY "' render scene.json -o out.png --quiet 2>err.txt";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
  std::ifstream in(dir.file("err.txt"));
  const std::string err((std::istreambuf_iterator<char>(in)), {});
  EXPECT_EQ(err,
            "scene.json: /media/fire/emission/file: fire.vdb: cannot open file (No such "
            "file or directory)\n");
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.png")));
}

}  // namespace temperature_emission_test
}  // namespace nimbus
