// Spectral mode (issue 8) against references: white furnaces with chromatic (upsampled)
// coefficients for every tracking family, Chandrasekhar's half-space with a per-wavelength
// albedo integrated against the CIE observer, and a grey scene that must render the same in rgb
// and spectral modes.

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "nimbus/frep/primitives.h"
#include "nimbus/math/constants.h"
#include "nimbus/render/renderer.h"
#include "nimbus/spectral/cie.h"
#include "nimbus/spectral/color.h"
#include "nimbus/spectral/spectral_curve.h"
#include "nimbus/spectral/spectral_param.h"
#include "nimbus/spectral/wavelengths.h"
#include "support/chandrasekhar.h"
#include "support/scene_builders.h"
#include "support/stats.h"

namespace nimbus {
namespace {

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

class SpectralRender : public testing::TestWithParam<SpectralCase> {};

// A unit sphere holding `medium` (index-matched) under a white environment (D65 in spectral
// mode), rendered with the case's tracking and wavelength count.
RenderResult render_furnace(const SpectralCase& c, const Medium& medium, uint64_t seed) {
  Scene scene;
  scene.settings = {12, 12, 64, seed, 100000, tracking_of(c), spectral(c.wavelengths)};
  scene.camera = perspective_camera({0, 0.3, 3.5}, {0, 0, 0}, {0, 1, 0}, 40, 12, 12);
  scene.media.push_back(medium);
  scene.objects.push_back(
      test::object_of(make_shape(QuadricNode{sphere({0, 0, 0}, 1)}), Surface::Type::None, 0));
  scene.lights.push_back(test::environment(1.0));
  test::finish_media(scene);
  return render(scene);
}

// The image of a furnace in equilibrium: the sRGB of D65 (white) everywhere.
void expect_d65_white(const RenderResult& r) {
  const Rgb ref = film_value([&](double l) { return d65_illuminant(l); });
  const MeanEstimate est = image_mean(r.film);
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_NEAR(ref[ch], 1.0, 2e-3) << "D65 is sRGB's white";
    EXPECT_GT(est.standard_error[ch], 0);
    EXPECT_NEAR(est.mean[ch], ref[ch], 4 * est.standard_error[ch]) << "channel " << ch;
  }
}

// An albedo-1 medium with chromatic sigma_s (upsampled from RGB (1, 3, 6)) under a white
// environment: every wavelength sees L = D65, so the image is the sRGB of D65, white.
TEST_P(SpectralRender, WhiteFurnace) {
  const SpectralCase& c = GetParam();
  if (c.mode == Mode::SpectralMax) GTEST_SKIP() << "the max rule has infinite variance here";
  Medium m;
  m.sigma_s = Rgb({1.0, 3.0, 6.0});
  m.g = 0.4;
  const RenderResult r = render_furnace(c, m, 5);
  expect_d65_white(r);
  EXPECT_GT(r.counters.scatter_events, 1000u);
}

// Kirchhoff in spectral mode: a chromatic medium that emits L_e = D65 (RGB 1) wherever it
// absorbs, under an environment of the same spectrum, is in equilibrium at every wavelength.
TEST_P(SpectralRender, EmissiveFurnaceIsInEquilibrium) {
  Medium m;
  m.sigma_s = Rgb({4.0, 1.0, 6.0});
  m.sigma_a = Rgb({2.0, 4.0, 0.5});
  m.emission = Rgb(1.0);
  m.density = Medium::Density::Cloud;
  m.cloud = make_cloud_density(CloudParams{});
  const RenderResult r = render_furnace(GetParam(), m, 6);
  expect_d65_white(r);
  EXPECT_GT(r.counters.real_collisions, 1000u);
}

// Chandrasekhar's half-space (as in media_render_test.cpp) with a sampled albedo ω(λ):
// sigma_s = ω, sigma_a = 1 − ω (both piecewise linear on the same knots, so mu_t = 1), lit by a
// sun of constant irradiance 2. The reference integrates the exact reflection per wavelength.
TEST_P(SpectralRender, ChandrasekharHalfSpace) {
  const SpectralCase& c = GetParam();
  const double mu0 = 1.0, mu = std::cos(30 * kPi / 180);
  const std::vector<std::pair<double, double>> albedo = {
      {360, 0.3}, {450, 0.95}, {520, 0.6}, {600, 0.85}, {830, 0.4}};
  std::vector<std::pair<double, double>> absorption;
  for (const auto& [nm, w] : albedo) absorption.emplace_back(nm, 1 - w);
  Medium m;
  m.sigma_s.curve.emplace(piecewise_linear_spectrum(albedo));
  m.sigma_a.curve.emplace(piecewise_linear_spectrum(absorption));
  SpectralParam sun(Rgb(2.0));
  sun.curve = constant_spectrum(2.0);
  const Scene scene = test::half_space_scene(
      0, 30, m, sun, {6, 6, 2048, 3, 100000, tracking_of(c), spectral(c.wavelengths)});
  const SpectralCurve omega = *scene.media[0].sigma_s.curve;
  const Rgb ref = film_value(
      [&](double l) { return test::half_space_reflected_radiance(2.0, omega(l), mu0, mu); });
  const RenderResult r = render(scene);
  const MeanEstimate est = image_mean(r.film);
  for (int ch = 0; ch < 3; ++ch)
    EXPECT_NEAR(est.mean[ch], ref[ch], 4 * est.standard_error[ch]) << "channel " << ch;
}

// Spectral MIS in its own form, delta tracking (Woodcock) and the paper's history rule with and
// without decomposition at N = 4, 8 and 16; the history rule with absorption events and the max
// rule (Chandrasekhar only: its weights grow without bound in a furnace) at N = 8.
std::vector<SpectralCase> spectral_cases() {
  std::vector<SpectralCase> out;
  for (int n : {4, 8, 16}) {
    out.push_back({Mode::Delta, Absorption::Collide, false, n});
    out.push_back({Mode::SpectralHistory, Absorption::Weight, true, n});
    out.push_back({Mode::SpectralMis, Absorption::Collide, false, n});
  }
  out.push_back({Mode::SpectralHistory, Absorption::Collide, false, 8});
  out.push_back({Mode::SpectralMax, Absorption::Collide, false, 8});
  return out;
}

INSTANTIATE_TEST_SUITE_P(Modes, SpectralRender, testing::ValuesIn(spectral_cases()), case_name);

// A convex diffuse object under a uniform environment reflects albedo × environment at every
// wavelength: a sampled albedo under a 4000 K blackbody sky, seen only where the sphere is.
TEST(SpectralRenderSurfaces, SampledAlbedoUnderABlackbodySky) {
  Scene scene;
  scene.settings = {
      8,          8,    256,
      13,         1000, test::tracking_settings(Mode::SpectralMis, Absorption::Collide, false, 0),
      spectral(8)};
  scene.camera = orthographic_camera({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.6, 8, 8);
  SceneObject ball =
      test::object_of(make_shape(QuadricNode{sphere({0, 0, 0}, 1)}), Surface::Type::Diffuse, -1);
  ball.surface.albedo = from_curve(
      piecewise_linear_spectrum({{400, 0.2}, {480, 0.9}, {560, 0.3}, {640, 0.7}, {700, 0.1}}),
      SpectralRole::Albedo);
  scene.objects.push_back(std::move(ball));
  Light sky;
  sky.type = Light::Type::Environment;
  sky.emission = from_curve(blackbody_spectrum(4000, 1.5), SpectralRole::Illuminant);
  scene.lights.push_back(sky);
  test::finish_media(scene);
  const SpectralCurve albedo = *scene.objects[0].surface.albedo.curve;
  const SpectralCurve sky_curve = *scene.lights[0].emission.curve;
  const Rgb ref = film_value([&](double l) { return albedo(l) * sky_curve(l); });
  const RenderResult r = render(scene);
  const MeanEstimate est = image_mean(r.film);
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_GT(est.standard_error[ch], 0);
    EXPECT_NEAR(est.mean[ch], ref[ch], 4 * est.standard_error[ch]) << "channel " << ch;
  }
  // Its rgb-mode projection is a different, cruder answer: the product of the projections.
  EXPECT_GT(
      std::abs(ref[1] - scene.objects[0].surface.albedo.rgb[1] * scene.lights[0].emission.rgb[1]),
      1e-3);
}

// A grey scene (grey cloud, grey diffuse floor, white sun and sky) has the same expected image
// in rgb and spectral modes: every spectrum in it is a constant or D65 times one.
Scene grey_scene(const SpectralSettings& spectrum) {
  Scene scene;
  const TrackingSettings t =
      test::tracking_settings(Mode::SpectralMis, Absorption::Collide, false, 4);
  scene.settings = {8, 8, 512, 11, 100000, t, {}};
  scene.settings.spectral = spectrum;
  scene.camera = perspective_camera({0, 1.2, 4}, {0, 0, 0}, {0, 1, 0}, 45, 8, 8);
  Medium cloud;
  cloud.sigma_s = Rgb(3.0);
  cloud.sigma_a = Rgb(0.5);
  cloud.density = Medium::Density::Cloud;
  cloud.cloud = make_cloud_density(CloudParams{});
  scene.media.push_back(cloud);
  scene.objects.push_back(
      test::object_of(make_shape(QuadricNode{sphere({0, 0.2, 0}, 1)}), Surface::Type::None, 0));
  SceneObject floor = test::object_of(box({-3, -1.1, -3}, {3, -1, 3}), Surface::Type::Diffuse, -1);
  floor.surface.albedo = Rgb(0.6);
  scene.objects.push_back(std::move(floor));
  Light sun;
  sun.type = Light::Type::Directional;
  sun.direction = normalize(Vec3{-0.5, -1, -0.3});
  sun.emission = Rgb(2.0);
  scene.lights.push_back(sun);
  scene.lights.push_back(test::environment(0.3));
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
      EXPECT_NEAR(a.mean[ch], b.mean[ch], 4 * se) << "N " << n << " channel " << ch;
    }
    // Pixel by pixel too: the z-scores' sum of squares is chi-square.
    double chi2 = 0;
    int dof = 0;
    for (int p = 0; p < 64; ++p) {
      const Rgb va = rgb.film.variance_of_mean(p), vb = spec.film.variance_of_mean(p);
      for (int ch = 0; ch < 3; ++ch) {
        if (va[ch] + vb[ch] <= 0) continue;
        const double d = rgb.film.mean(p)[ch] - spec.film.mean(p)[ch];
        chi2 += d * d / (va[ch] + vb[ch]);
        ++dof;
      }
    }
    ASSERT_GT(dof, 100);
    EXPECT_LT(chi2, test::chi_square_critical(dof, 1e-4)) << "N " << n;
  }
}

// A spectral render is deterministic and independent of the thread count.
TEST(SpectralRenderGrey, SameImageForAnyThreadCount) {
  Scene scene = grey_scene(spectral(8));
  scene.settings.spp = 8;
  const RenderResult one = render(scene, {1, {}});
  const RenderResult two = render(scene, {2, {}});
  for (int p = 0; p < 64; ++p) EXPECT_TRUE(one.film.sum[p] == two.film.sum[p]) << p;
}

// A channel count outside 4..16 is refused with a message, not rendered.
TEST(SpectralRenderGrey, WavelengthCountOutOfRangeIsRefused) {
  Scene scene = grey_scene(spectral(3));
  EXPECT_THROW(render(scene), std::invalid_argument);
}

}  // namespace
}  // namespace nimbus
