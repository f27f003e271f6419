// Spectral mode (issue 8) against references: white furnaces with chromatic (upsampled)
// coefficients for every tracking family, Chandrasekhar's half-space with a per-wavelength
// albedo integrated against the CIE observer, and a grey scene that must render the same in rgb
// and spectral modes.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "nimbus/frep/primitives.h"
#include "nimbus/math/constants.h"
#include "nimbus/media/cloud_density.h"
#include "nimbus/render/renderer.h"
#include "nimbus/render/wavelength_counts.h"
#include "nimbus/spectral/cie.h"
#include "nimbus/spectral/color.h"
#include "nimbus/spectral/spectral_curve.h"
#include "nimbus/spectral/spectral_param.h"
#include "nimbus/spectral/wavelengths.h"
#include "support/chandrasekhar.h"
#include "support/film_chi2.h"
#include "support/scene_builders.h"
#include "support/stats.h"
#include "support/weight_growth.h"

namespace nimbus {
namespace spectral_render_test {

using Mode = TrackingSettings::Mode;
using Absorption = TrackingSettings::Absorption;

// A tracking family and a wavelength count.
struct SpectralCase {
  Mode mode;
  Absorption absorption;
  bool decomposition;
  int wavelengths;
};

TrackingSettings tracking_of(const SpectralCase& c) {
  return test::tracking_settings(c.mode, c.absorption, c.decomposition, 4);
}

std::string case_name(const testing::TestParamInfo<SpectralCase>& info) {
  const SpectralCase& c = info.param;
  const char* mode = c.mode == Mode::Delta             ? "Delta"
                     : c.mode == Mode::SpectralMax     ? "SpectralMax"
                     : c.mode == Mode::SpectralHistory ? "SpectralHistory"
                                                       : "SpectralMis";
  return std::string(mode) + (c.absorption == Absorption::Collide ? "Collide" : "Weight") +
         (c.decomposition ? "Decomposition" : "") + "N" + std::to_string(c.wavelengths);
}

SpectralSettings spectral(int wavelengths) {
  return {SpectralSettings::Mode::Spectral, wavelengths};
}

// The expected film value of a path that carries L(λ) at every wavelength: linear sRGB of
// ∫ L (x̄, ȳ, z̄) dλ / ∫ ȳ, by the trapezoid rule at 0.5 nm.
template <class L>
Rgb film_value(L&& radiance) {
  Vec3 xyz;
  const double h = 0.5;
  for (double lambda = kLambdaMin; lambda <= kLambdaMax + 1e-9; lambda += h) {
    const double w = (lambda == kLambdaMin || lambda + h > kLambdaMax + 1e-9) ? 0.5 * h : h;
    xyz += cie_xyz_bar(lambda) * (radiance(lambda) * w);
  }
  return xyz_to_linear_srgb(xyz * (1.0 / cie_y_integral()));
}

class SpectralRender : public testing::TestWithParam<SpectralCase> {
 protected:
  // A build may render fewer wavelength counts (the sanitized build of tools/sanitize.sh: 4 and 8,
  // the counts' code being one template); the Release build runs every case.
  void SetUp() override {
    if (!is_built_wavelength_count(GetParam().wavelengths))
      GTEST_SKIP() << "this build renders no " << GetParam().wavelengths
                   << " wavelengths (NIMBUS_WAVELENGTH_COUNTS)";
  }
};

// Bounds on the standard error of an image mean, about twice the largest measured over the
// modes each test runs.
constexpr double kWhiteFurnaceSE = 0.05, kEmissiveFurnaceSE = 0.02, kChandrasekharSE = 0.006;

// A unit sphere holding `medium` (index-matched) under a white environment (D65 in spectral
// mode), with the case's tracking and wavelength count.
// The tests here take their tolerances from sample variances, which estimate the variance of a
// mean for independent samples only: every scene asks for the independent sampler (the default
// sampler meets these references in sampler_render_test.cpp).
Scene furnace_scene(const SpectralCase& c, const Medium& medium, uint64_t seed, int spp = 64) {
  Scene scene;
  scene.settings = {12,
                    12,
                    spp,
                    seed,
                    100000,
                    tracking_of(c),
                    spectral(c.wavelengths),
                    RenderSettings::Sampler::Independent};
  scene.camera = perspective_camera({0, 0.3, 3.5}, {0, 0, 0}, {0, 1, 0}, 40, 12, 12);
  scene.media.push_back(medium);
  scene.objects.push_back(
      test::object_of(make_shape(QuadricNode{sphere({0, 0, 0}, 1)}), Surface::Type::None, 0));
  scene.lights.push_back(test::environment(1.0));
  test::finish_media(scene);
  return scene;
}

// Why a case cannot be checked on the scene's medium (media[0]), or nothing: the criterion of
// media_render_test.cpp (support/weight_growth.h) for the channel and max rules in a medium
// where paths scatter without bound, on the medium's spectra at every 5 nm.
std::optional<std::string> unfit(const SpectralCase& c, const Scene& scene, bool homogeneous) {
  if (c.mode != Mode::Delta && c.mode != Mode::SpectralMax) return std::nullopt;
  const Medium& m = scene.media[0];
  test::Channels a, sc;
  for (double l = kLambdaMin; l <= kLambdaMax; l += 5) {
    a.push_back((*m.sigma_a.curve)(l));
    sc.push_back((*m.sigma_s.curve)(l));
  }
  const double rho =
      test::medium_growth(c.mode == Mode::Delta ? EventRule::Channel : EventRule::Max, a, sc,
                          homogeneous, 1.0, c.decomposition, c.absorption == Absorption::Collide);
  if (rho <= 1 + 1e-9) return std::nullopt;
  return "the weights' second moment grows by rho = " + std::to_string(rho) +
         " > 1 per tentative collision, and paths scatter without bound";
}

#define SKIP_IF_UNFIT(scene, homogeneous) \
  if (const auto why = unfit(GetParam(), scene, homogeneous); why) GTEST_SKIP() << *why

// An image mean against a reference: within 4 standard errors, a standard error below
// `se_bound`, and a render of a deliberately wrong scene told apart (power).
void expect_mean(const RenderResult& r, const RenderResult& wrong, const Rgb& ref,
                 double se_bound) {
  // Issue 13: no sample may reach the film as NaN or infinity (the film would refuse it).
  EXPECT_EQ(r.counters.rejected_samples, 0u);
  EXPECT_EQ(wrong.counters.rejected_samples, 0u);
  const MeanEstimate est = image_mean(r.film), bad = image_mean(wrong.film);
  double z_wrong = 0;
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_GT(est.standard_error[ch], 0);
    EXPECT_LT(est.standard_error[ch], se_bound) << "channel " << ch;
    EXPECT_NEAR(est.mean[ch], ref[ch], 4 * est.standard_error[ch]) << "channel " << ch;
    z_wrong = std::max(z_wrong, std::abs(bad.mean[ch] - ref[ch]) / bad.standard_error[ch]);
  }
  EXPECT_GT(z_wrong, 4) << "the test cannot see a wrong medium";
}

// The image of a furnace in equilibrium: the sRGB of D65 (white) everywhere.
Rgb d65_white() {
  const Rgb ref = film_value([&](double l) { return d65_illuminant(l); });
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(ref[ch], 1.0, 2e-3) << "D65 is sRGB's white";
  return ref;
}

// An albedo-1 medium with chromatic sigma_s (upsampled from RGB (1, 3, 6)) under a white
// environment: every wavelength sees L = D65, so the image is the sRGB of D65, white. The power
// check: 5 % of the extinction absorbing.
TEST_P(SpectralRender, WhiteFurnace) {
  const SpectralCase& c = GetParam();
  Medium m;
  m.sigma_s = Rgb({1.0, 3.0, 6.0});
  m.g = 0.4;
  const Scene scene = furnace_scene(c, m, 5);
  SKIP_IF_UNFIT(scene, true);
  const RenderResult r = render(scene);
  m.sigma_a = m.sigma_s.rgb * 0.05;
  expect_mean(r, render(furnace_scene(c, m, 5)), d65_white(), kWhiteFurnaceSE);
  EXPECT_GT(r.counters.scatter_events, 1000u);
}

// Kirchhoff in spectral mode: a chromatic medium that emits L_e = D65 (RGB 1) wherever it
// absorbs, under an environment of the same spectrum, is in equilibrium at every wavelength.
// The power check: emission 0.9 (512 spp, so that delta tracking sees it).
TEST_P(SpectralRender, EmissiveFurnaceIsInEquilibrium) {
  const SpectralCase& c = GetParam();
  Medium m;
  m.sigma_s = Rgb({4.0, 1.0, 6.0});
  m.sigma_a = Rgb({2.0, 4.0, 0.5});
  m.emission = Rgb(1.0);
  m.density = make_cloud_density(CloudParams{});
  const Scene scene = furnace_scene(c, m, 6, 512);
  SKIP_IF_UNFIT(scene, false);
  const RenderResult r = render(scene);
  m.emission = Rgb(0.9);
  expect_mean(r, render(furnace_scene(c, m, 6, 512)), d65_white(), kEmissiveFurnaceSE);
  EXPECT_GT(r.counters.real_collisions, 1000u);
}

// Chandrasekhar's half-space (as in media_render_test.cpp) with a sampled albedo ω(λ):
// sigma_s = ω, sigma_a = 1 − ω (both piecewise linear on the same knots, so mu_t = 1), lit by a
// sun of constant irradiance 2. The reference integrates the exact reflection per wavelength.
// The power check renders albedos 5 % lower.
Scene half_space(const SpectralCase& c, double albedo_scale) {
  const std::vector<std::pair<double, double>> knots = {
      {360, 0.3}, {450, 0.95}, {520, 0.6}, {600, 0.85}, {830, 0.4}};
  std::vector<std::pair<double, double>> albedo, absorption;
  for (const auto& [nm, w] : knots) {
    albedo.emplace_back(nm, w * albedo_scale);
    absorption.emplace_back(nm, 1 - w * albedo_scale);
  }
  Medium m;
  m.sigma_s.curve.emplace(piecewise_linear_spectrum(albedo));
  m.sigma_a.curve.emplace(piecewise_linear_spectrum(absorption));
  SpectralParam sun(Rgb(2.0));
  sun.curve = constant_spectrum(2.0);
  return test::half_space_scene(0, 30, m, sun,
                                {6, 6, 2048, 3, 100000, tracking_of(c), spectral(c.wavelengths),
                                 RenderSettings::Sampler::Independent});
}

TEST_P(SpectralRender, ChandrasekharHalfSpace) {
  const SpectralCase& c = GetParam();
  const double mu0 = 1.0, mu = std::cos(30 * kPi / 180);
  const Scene scene = half_space(c, 1.0);
  SKIP_IF_UNFIT(scene, true);
  const SpectralCurve omega = *scene.media[0].sigma_s.curve;
  const Rgb ref = film_value(
      [&](double l) { return test::half_space_reflected_radiance(2.0, omega(l), mu0, mu); });
  expect_mean(render(scene), render(half_space(c, 0.95)), ref, kChandrasekharSE);
}

// Spectral MIS in its own form, delta tracking (Woodcock) and the paper's history rule with and
// without decomposition at N = 4, 8 and 16; the history rule with absorption events and the max
// rule with and without them at N = 8. Which of them a test can check is decided in the test
// (`unfit`).
std::vector<SpectralCase> spectral_cases() {
  std::vector<SpectralCase> out;
  for (int n : {4, 8, 16}) {
    out.push_back({Mode::Delta, Absorption::Collide, false, n});
    out.push_back({Mode::SpectralHistory, Absorption::Weight, true, n});
    out.push_back({Mode::SpectralMis, Absorption::Collide, false, n});
  }
  out.push_back({Mode::SpectralHistory, Absorption::Collide, false, 8});
  out.push_back({Mode::SpectralMax, Absorption::Collide, false, 8});
  out.push_back({Mode::SpectralMax, Absorption::Weight, false, 8});
  return out;
}

INSTANTIATE_TEST_SUITE_P(Modes, SpectralRender, testing::ValuesIn(spectral_cases()), case_name);

// A convex diffuse object under a uniform environment reflects albedo × environment at every
// wavelength: a sampled albedo under a 4000 K blackbody sky, seen only where the sphere is.
Scene ball_under_sky(double albedo_scale) {
  Scene scene;
  scene.settings = {
      8,           8,
      256,         13,
      1000,        test::tracking_settings(Mode::SpectralMis, Absorption::Collide, false, 0),
      spectral(8), RenderSettings::Sampler::Independent};
  scene.camera = orthographic_camera({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.6, 8, 8);
  SceneObject ball =
      test::object_of(make_shape(QuadricNode{sphere({0, 0, 0}, 1)}), Surface::Type::Diffuse, -1);
  std::vector<std::pair<double, double>> albedo = {
      {400, 0.2}, {480, 0.9}, {560, 0.3}, {640, 0.7}, {700, 0.1}};
  for (auto& knot : albedo) knot.second *= albedo_scale;
  ball.surface.albedo = from_curve(piecewise_linear_spectrum(albedo), SpectralRole::Albedo);
  scene.objects.push_back(std::move(ball));
  Light sky;
  sky.type = Light::Type::Environment;
  sky.emission = from_curve(blackbody_spectrum(4000, 1.5), SpectralRole::Illuminant);
  scene.lights.push_back(sky);
  test::finish_media(scene);
  return scene;
}

TEST(SpectralRenderSurfaces, SampledAlbedoUnderABlackbodySky) {
  const Scene scene = ball_under_sky(1.0);
  const SpectralCurve albedo = *scene.objects[0].surface.albedo.curve;
  const SpectralCurve sky_curve = *scene.lights[0].emission.curve;
  const Rgb ref = film_value([&](double l) { return albedo(l) * sky_curve(l); });
  // Standard errors measured 0.0016–0.0029; the power check: albedos 5 % lower.
  expect_mean(render(scene), render(ball_under_sky(0.95)), ref, 0.006);
  // Its rgb-mode projection is a different, cruder answer: the product of the projections.
  EXPECT_GT(
      std::abs(ref[1] - scene.objects[0].surface.albedo.rgb[1] * scene.lights[0].emission.rgb[1]),
      1e-3);
}

// A grey scene (grey cloud, grey diffuse floor, white sun and sky) has the same expected image
// in rgb and spectral modes: every spectrum in it is a constant or D65 times one.
Scene grey_scene(const SpectralSettings& spectrum, double light_scale = 1) {
  Scene scene;
  const TrackingSettings t =
      test::tracking_settings(Mode::SpectralMis, Absorption::Collide, false, 4);
  scene.settings = {8, 8, 512, 11, 100000, t, {}, RenderSettings::Sampler::Independent};
  scene.settings.spectral = spectrum;
  scene.camera = perspective_camera({0, 1.2, 4}, {0, 0, 0}, {0, 1, 0}, 45, 8, 8);
  Medium cloud;
  cloud.sigma_s = Rgb(3.0);
  cloud.sigma_a = Rgb(0.5);
  cloud.density = make_cloud_density(CloudParams{});
  scene.media.push_back(cloud);
  scene.objects.push_back(
      test::object_of(make_shape(QuadricNode{sphere({0, 0.2, 0}, 1)}), Surface::Type::None, 0));
  SceneObject floor = test::object_of(box({-3, -1.1, -3}, {3, -1, 3}), Surface::Type::Diffuse, -1);
  floor.surface.albedo = Rgb(0.6);
  scene.objects.push_back(std::move(floor));
  Light sun;
  sun.type = Light::Type::Directional;
  sun.direction = normalize(Vec3{-0.5, -1, -0.3});
  sun.emission = Rgb(2.0 * light_scale);
  scene.lights.push_back(sun);
  scene.lights.push_back(test::environment(0.3 * light_scale));
  test::finish_media(scene);
  return scene;
}

TEST(SpectralRenderGrey, RgbAndSpectralModesAgree) {
  const RenderResult rgb = render(grey_scene({}));
  for (int n : {4, 8}) {
    const RenderResult spec = render(grey_scene(spectral(n)));
    const MeanEstimate a = image_mean(rgb.film), b = image_mean(spec.film);
    for (int ch = 0; ch < 3; ++ch) {
      const double se = std::hypot(a.standard_error[ch], b.standard_error[ch]);
      EXPECT_GT(se, 0);
      EXPECT_LT(se, 0.004) << "N " << n << " channel " << ch;  // measured 0.0010–0.0017
      EXPECT_NEAR(a.mean[ch], b.mean[ch], 4 * se) << "N " << n << " channel " << ch;
    }
    // Pixel by pixel too: the z-scores' sum of squares is chi-square.
    const test::Chi2 chi2 = test::film_chi2(rgb.film, spec.film);
    ASSERT_GT(chi2.dof, 100);
    EXPECT_TRUE(chi2.passes()) << "N " << n << ": chi2 " << chi2.value << " over " << chi2.dof;
    // Power: a spectral render of a cloud 10 % denser is told apart.
    // Power: a spectral render whose lights are 5 % too bright (the size of an error in the
    // illuminant's normalisation) is told apart. (A 10 % denser cloud is not: chi-square 164
    // over 192 at N = 4; this image hardly depends on the cloud's density.)
    EXPECT_FALSE(test::film_chi2(rgb.film, render(grey_scene(spectral(n), 1.05)).film).passes())
        << "N " << n;
  }
}

// A spectral render is deterministic and independent of the thread count.
TEST(SpectralRenderGrey, SameImageForAnyThreadCount) {
  Scene scene = grey_scene(spectral(8));
  scene.settings.spp = 8;
  const RenderResult one = render(scene, RenderOptions{1, {}, {}, {}});
  const RenderResult two = render(scene, RenderOptions{2, {}, {}, {}});
  for (int p = 0; p < 64; ++p) EXPECT_TRUE(one.film.sum[p] == two.film.sum[p]) << p;
}

// A channel count outside 4..16 is refused with a message, not rendered.
TEST(SpectralRenderGrey, WavelengthCountOutOfRangeIsRefused) {
  Scene scene = grey_scene(spectral(3));
  EXPECT_THROW(render(scene), std::invalid_argument);
}

}  // namespace spectral_render_test
}  // namespace nimbus
