// The volumetric path tracer against analytic references (issue 4): transmittance through an
// emitting field-density absorber, white and emissive furnaces, and Chandrasekhar's
// semi-infinite medium; each for every tracking mode and combination (issue 5), and, on a
// heterogeneous chromatic cloud, every mode agrees with delta tracking.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "nimbus/frep/primitives.h"
#include "nimbus/math/constants.h"
#include "nimbus/render/renderer.h"
#include "support/chandrasekhar.h"
#include "support/film_chi2.h"
#include "support/scene_builders.h"
#include "support/stats.h"

namespace nimbus {
namespace {

// One combination of the integrator's tracking settings.
struct ModeCase {
  TrackingSettings::Mode mode;
  TrackingSettings::Absorption absorption;
  bool decomposition;
  double majorant_scale;
  int octree_depth;
  bool sampled_majorant = false;  // the paper's short sampling pass instead of interval bounds
};

TrackingSettings tracking_of(const ModeCase& c) {
  TrackingSettings t =
      test::tracking_settings(c.mode, c.absorption, c.decomposition, c.octree_depth);
  t.majorant_scale = c.majorant_scale;
  if (c.sampled_majorant) {
    t.majorant_source = TrackingSettings::MajorantSource::Sample;
    t.majorant_samples = 64;  // few, so that some leaves' majorants miss the maximum
  }
  return t;
}

std::string mode_name(const testing::TestParamInfo<ModeCase>& info) {
  using M = TrackingSettings::Mode;
  const ModeCase& c = info.param;
  const char* mode = c.mode == M::Delta             ? "Delta"
                     : c.mode == M::SpectralMax     ? "SpectralMax"
                     : c.mode == M::SpectralHistory ? "SpectralHistory"
                                                    : "SpectralMis";
  return std::string(mode) +
         (c.absorption == TrackingSettings::Absorption::Collide ? "Collide" : "Weight") +
         (c.decomposition ? "Decomposition" : "") + (c.majorant_scale < 1 ? "Unbounded" : "") +
         (c.sampled_majorant ? "Sampled" : "") + "Depth" + std::to_string(c.octree_depth);
}

// Every mode with absorption events or weights, with and without decomposition; the spectral
// modes also with majorants scaled by 0.5, which do not bound. Not delta tracking there:
// Woodcock's clamps (biased by design), and its weighted form, though unbiased, has weights
// growing like 3^k (tests/spectral_tracking_test.cpp); nor spectral MIS, which clamps. Spectral
// MIS in its own form (absorption events, no decomposition). All at octree depth 4; the baseline
// and the paper's method also at depths 0 (one node) and 12.
std::vector<ModeCase> mode_cases() {
  using M = TrackingSettings::Mode;
  using A = TrackingSettings::Absorption;
  std::vector<ModeCase> out;
  for (M mode : {M::Delta, M::SpectralMax, M::SpectralHistory})
    for (A absorption : {A::Collide, A::Weight})
      for (bool decomposition : {false, true})
        for (double scale : {1.0, 0.5})
          if (mode != M::Delta || scale == 1)
            out.push_back({mode, absorption, decomposition, scale, 4});
  out.push_back({M::SpectralMis, A::Collide, false, 1.0, 4});
  // The paper's method with majorants and minorants from its sampling pass (may not bound).
  out.push_back({M::SpectralHistory, A::Weight, true, 1.0, 4, true});
  for (int depth : {0, 12}) {
    out.push_back({M::Delta, A::Collide, false, 1.0, depth});
    out.push_back({M::SpectralHistory, A::Weight, true, 1.0, depth});
  }
  return out;
}

class MediaRender : public testing::TestWithParam<ModeCase> {
 protected:
  TrackingSettings tracking() const { return tracking_of(GetParam()); }
  // The max rule (eq. 6–9) in a constant, albedo-1 medium with sigma_s = (1, 3, 6) has infinite
  // variance: where mu_t is constant the majorant 6 leaves channel 2 no null coefficient, so its
  // weight survives only along scatter-only runs, k scatters having probability (6/11)^k and
  // weight (11/6)^k; the second moment Σ (11/6)^k diverges. The sample mean then falls short by
  // many "standard errors" (0.92 ± 0.01 at 8192 spp) and inside a lossless dielectric, where
  // only Russian roulette on the growing weights ends a path, paths hardly end. This is the
  // growth of the weights that the history rule (eq. 10–13) was made to prevent.
  bool max_rule() const { return GetParam().mode == TrackingSettings::Mode::SpectralMax; }
  // With mu_bar = mu_t / 2 every tentative collision multiplies |w| by about
  // (|mu_s| + |mu_n|)/mu_bar = 3 (the sign alternates; the expectation is right), so in an
  // optically infinite half-space the weights grow without bound and Russian roulette on them
  // never ends a path: unbiased, but of unbounded variance and cost. Non-bounding majorants are
  // tested on the finite media.
  bool unbounded() const { return GetParam().majorant_scale < 1; }
};

// An absorber of density 1 − |x|² in the unit sphere, emitting L_e, before an environment of
// radiance 1: L = T + L_e (1 − T) along each ray.
TEST_P(MediaRender, EmittingFieldAbsorberMatchesClosedForm) {
  const Rgb sigma_a({0.5, 1.0, 2.0}), L_e({0.5, 2.0, 1.0});
  const int size = 20;
  Scene scene;
  // 1024 spp: with fewer, the per-pixel sample variances of the weighted trackers' heavy-tailed
  // estimates are too noisy for the chi-square of z-scores to hold its nominal level.
  scene.settings = {size, size, 1024, 11, 100, tracking(), {}};
  const double view = 2.2;
  scene.camera = orthographic_camera({0, 0, 4}, {0, 0, 0}, {0, 1, 0}, view, size, size);
  scene.lights.push_back(test::environment(1.0));
  Medium absorber;
  absorber.sigma_a = sigma_a;
  absorber.emission = L_e;
  absorber.density = Medium::Density::Field;
  absorber.scale = 1.0;
  scene.media.push_back(absorber);
  scene.objects.push_back(
      test::object_of(make_shape(QuadricNode{sphere({0, 0, 0}, 1)}), Surface::Type::None, 0));
  test::finish_media(scene);
  const RenderResult r = render(scene);

  // The reference averaged over each pixel's footprint: ∫ (1 − b² − s²) ds over the chord is
  // 4/3 (1 − b²)^{3/2}.
  auto T = [&](double b2, int c) {
    return b2 >= 1 ? 1.0 : std::exp(-sigma_a[c] * 4.0 / 3.0 * std::pow(1 - b2, 1.5));
  };
  double chi2 = 0;
  int dof = 0;
  const double px = view / size;
  auto inside_disc = [&](int x, int y) {
    for (int cx : {x, x + 1})
      for (int cy : {y, y + 1}) {
        const double sx = -view / 2 + cx * px, sy = view / 2 - cy * px;
        if (sx * sx + sy * sy >= 1) return false;
      }
    return true;
  };
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
            const double t = T(sx * sx + sy * sy, c);
            ref += t + L_e[c] * (1 - t);
          }
        ref /= k * k;
        double var = r.film.variance_of_mean(p)[c];
        if (var <= 0) {
          // No path met the medium, or every estimate is exact.
          if (std::abs(r.film.mean(p)[c] - ref) <= 1e-3) continue;
          // Otherwise every sample of the pixel-channel came out the same by chance (all
          // absorbed): bound the variance by Bhatia–Davis for delta tracking's samples in
          // [0, 3 max(1, L_e)] and count the pixel like the others.
          var = ref * (3 * std::max(1.0, L_e.max()) - ref) / scene.settings.spp;
        }
        // Pixels across the disc's rim are skipped: there only the few samples that meet the
        // medium at all differ from 1, and the sample variance of 256 such samples is no
        // estimate of the variance (weighted trackers have no per-channel selection noise
        // outside the disc to mask this; delta tracking has).
        if (!inside_disc(x, y)) continue;
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
void expect_white_furnace(Scene& scene) {
  scene.lights.push_back(test::environment(1.0));
  test::finish_media(scene);
  const RenderResult r = render(scene);
  const MeanEstimate m = image_mean(r.film);
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(m.standard_error[c], 0) << "the medium must make some noise";
    EXPECT_NEAR(m.mean[c], 1.0, 4 * m.standard_error[c]) << "channel " << c;
  }
  EXPECT_GT(r.counters.scatter_events, 1000u);
}

Scene furnace_scene(Medium medium, Surface::Type surface, const ShapePtr& shape,
                    const TrackingSettings& tracking) {
  Scene scene;
  scene.settings = {12, 12, 64, 5, 100000, tracking, {}};
  scene.camera = perspective_camera({0, 0.3, 3.5}, {0, 0, 0}, {0, 1, 0}, 40, 12, 12);
  medium.sigma_a = Rgb(0.0);
  scene.media.push_back(medium);
  scene.objects.push_back(test::object_of(shape, surface, 0));
  return scene;
}

Medium chromatic_scatterer() {
  Medium m;
  m.sigma_s = Rgb({1.0, 3.0, 6.0});
  m.g = 0.4;
  return m;
}

TEST_P(MediaRender, WhiteFurnaceConstantDensityIndexMatched) {
  if (max_rule()) GTEST_SKIP() << "the max rule has infinite variance here";
  Scene s = furnace_scene(chromatic_scatterer(), Surface::Type::None,
                          make_shape(QuadricNode{sphere({0, 0, 0}, 1)}), tracking());
  expect_white_furnace(s);
}

TEST_P(MediaRender, WhiteFurnaceCloudDensityIndexMatched) {
  // The same growth of the max rule's weights, milder where the cloud leaves null collisions:
  // measured at 4096 spp, seed 5, the mean was 0.980 with a standard error hardly below that at
  // 1024 spp (the variance estimate grows with the sample count), seed 8 passed; the history rule
  // passes at every count tried.
  if (max_rule()) GTEST_SKIP() << "the max rule has infinite variance here";
  Medium cloud = chromatic_scatterer();
  cloud.density = Medium::Density::Cloud;
  cloud.sigma_s = Rgb({4.0, 8.0, 12.0});
  cloud.cloud = make_cloud_density(CloudParams{});
  Scene s = furnace_scene(cloud, Surface::Type::None, make_shape(QuadricNode{sphere({0, 0, 0}, 1)}),
                          tracking());
  expect_white_furnace(s);
}

// Kirchhoff: a medium that emits L_e = 1 wherever it absorbs, in an environment of radiance 1,
// is in equilibrium and renders 1 whatever its albedo (here chromatic and heterogeneous).
TEST_P(MediaRender, EmissiveFurnaceIsInEquilibrium) {
  Medium cloud = chromatic_scatterer();
  cloud.density = Medium::Density::Cloud;
  cloud.sigma_s = Rgb({4.0, 1.0, 6.0});
  cloud.cloud = make_cloud_density(CloudParams{});
  Scene s = furnace_scene(cloud, Surface::Type::None, make_shape(QuadricNode{sphere({0, 0, 0}, 1)}),
                          tracking());
  s.media[0].sigma_a = Rgb({2.0, 4.0, 0.5});
  s.media[0].emission = Rgb(1.0);
  expect_white_furnace(s);
}

TEST_P(MediaRender, WhiteFurnaceBehindLosslessDielectric) {
  if (max_rule()) GTEST_SKIP() << "the max rule has infinite variance here";
  Scene s = furnace_scene(chromatic_scatterer(), Surface::Type::Dielectric,
                          make_shape(QuadricNode{ellipsoid({0, 0, 0}, {1, 0.7, 0.9})}), tracking());
  expect_white_furnace(s);
}

// A half-space of isotropic scatterers (a sphere of radius 1000 seen near its top), lit by a
// directional light and seen from above: Chandrasekhar's exact diffuse reflection.
void expect_chandrasekhar(double theta0_deg, double theta_deg, const Rgb& albedo,
                          const TrackingSettings& tracking) {
  const double mu0 = std::cos(theta0_deg * kPi / 180), mu = std::cos(theta_deg * kPi / 180);
  Medium m;
  m.sigma_s = albedo;
  m.sigma_a = Rgb(1.0) - albedo;  // mu_t = 1
  const Scene scene = test::half_space_scene(theta0_deg, theta_deg, m, Rgb(2.0),
                                             {6, 6, 2048, 3, 100000, tracking, {}});
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
  if (unbounded()) GTEST_SKIP() << "unbounded variance in an infinite medium";
  expect_chandrasekhar(0, 30, Rgb({0.3, 0.7, 0.95}), tracking());
}

TEST_P(MediaRender, ChandrasekharHalfSpaceGrazingIncidence) {
  if (unbounded()) GTEST_SKIP() << "unbounded variance in an infinite medium";
  // Albedos (0.5, 0.9, 0.99), mu_t = mu_bar = 1: with absorption events the max rule scatters
  // with probability 0.99/1.49 and multiplies channel 2 by 1.49, so the k-th scattering order
  // carries second moment (0.66 · 1.49²)^k = 0.99^k·1.49^k: infinite variance again.
  if (max_rule() && GetParam().absorption == TrackingSettings::Absorption::Collide)
    GTEST_SKIP() << "the max rule with absorption events has infinite variance here";
  expect_chandrasekhar(60, 0, Rgb({0.5, 0.9, 0.99}), tracking());
}

// A heterogeneous chromatic cloud, uncorrelated per-channel sigma_s = (4, 12, 8), lit by a sun
// and a dim sky: no closed form, but every mode must render the same expected image.
Scene chromatic_cloud(const TrackingSettings& tracking, int spp) {
  Scene scene;
  scene.settings = {8, 8, spp, 21, 1000, tracking, {}};
  scene.camera = perspective_camera({0, 0.5, 3.2}, {0, 0, 0}, {0, 1, 0}, 45, 8, 8);
  Light sun;
  sun.type = Light::Type::Directional;
  sun.direction = normalize(Vec3{-0.4, -1, -0.3});
  sun.emission = Rgb(3.0);
  scene.lights.push_back(sun);
  scene.lights.push_back(test::environment(0.3));
  Medium cloud;
  cloud.density = Medium::Density::Cloud;
  cloud.sigma_s = Rgb({4.0, 12.0, 8.0});
  cloud.sigma_a = Rgb({0.2, 0.05, 0.4});
  cloud.g = 0.6;
  cloud.cloud = make_cloud_density(CloudParams{});
  scene.media.push_back(cloud);
  scene.objects.push_back(
      test::object_of(make_shape(QuadricNode{sphere({0, 0, 0}, 1)}), Surface::Type::None, 0));
  test::finish_media(scene);
  return scene;
}

// One test over all modes, so that the delta reference is rendered once per process.
TEST(MediaRenderModes, ChromaticCloudAgreesWithDeltaTracking) {
  const MeanEstimate delta = image_mean(render(chromatic_cloud({}, 512)).film);
  for (const ModeCase& mc : mode_cases()) {
    SCOPED_TRACE(mode_name({mc, 0}));
    const MeanEstimate m = image_mean(render(chromatic_cloud(tracking_of(mc), 128)).film);
    for (int c = 0; c < 3; ++c) {
      const double se = std::hypot(m.standard_error[c], delta.standard_error[c]);
      EXPECT_GT(m.standard_error[c], 0);
      EXPECT_NEAR(m.mean[c], delta.mean[c], 4 * se) << "channel " << c;
    }
  }
}

// A sphere light inside a scattering medium held by a solid of index 1 (a dielectric that
// neither reflects nor bends) must render as the same light in the same medium held by an
// index-matched object. The two take different estimators: inside a solid no light is sampled
// (its boundary is specular), so the light is found by phase sampling alone; in the field every
// scattering vertex samples the light and MIS weighs both. Issue 17: the solid's phase-sampled
// hits got the MIS weight of the light sampling it skipped, and lost most of the light.
Scene light_in_medium(Surface::Type surface, double density, TrackingSettings::Mode mode) {
  Scene scene;
  scene.settings = {
      8,  8,    1024,
      31, 1000, test::tracking_settings(mode, TrackingSettings::Absorption::Collide, false, 4),
      {}};
  scene.camera = orthographic_camera({0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 2.1, 8, 8);
  Medium m;
  m.sigma_s = Rgb({1.0, 2.0, 3.0}) * density;
  m.sigma_a = Rgb(1.0) * density;
  m.g = 0.3;
  scene.media.push_back(m);
  scene.objects.push_back(
      test::object_of(make_shape(QuadricNode{sphere({0, 0, 0}, 1)}), surface, 0, 1.0));
  Light bulb;
  bulb.type = Light::Type::Sphere;
  bulb.center = {0.2, 0.1, -0.1};
  bulb.radius = 0.45;
  bulb.emission = Rgb(3.0);
  scene.lights.push_back(bulb);
  test::finish_media(scene);
  return scene;
}

TEST(MediaRenderLights, LightInsideASolidMatchesTheSameLightInAField) {
  using M = TrackingSettings::Mode;
  for (M mode : {M::Delta, M::SpectralHistory, M::SpectralMis}) {
    SCOPED_TRACE(static_cast<int>(mode));
    const RenderResult solid = render(light_in_medium(Surface::Type::Dielectric, 1.0, mode));
    const RenderResult field = render(light_in_medium(Surface::Type::None, 1.0, mode));
    const test::Chi2 same = test::film_chi2(solid.film, field.film);
    EXPECT_GT(same.dof, 150);
    EXPECT_TRUE(same.passes()) << "chi2 " << same.value << " over " << same.dof;
    // Exploding variance would pass any chi-square: the image mean's error is bounded (it
    // measured 0.0023–0.0047 on a mean of 0.18).
    const MeanEstimate m = image_mean(solid.film);
    for (int c = 0; c < 3; ++c) EXPECT_LT(m.standard_error[c], 0.007) << "channel " << c;
    // Power: the same comparison sees a medium 10 % denser.
    const RenderResult denser = render(light_in_medium(Surface::Type::None, 1.1, mode));
    const test::Chi2 power = test::film_chi2(solid.film, denser.film);
    EXPECT_FALSE(power.passes()) << power.value << " " << power.dof;
  }
}

INSTANTIATE_TEST_SUITE_P(Modes, MediaRender, testing::ValuesIn(mode_cases()), mode_name);

}  // namespace
}  // namespace nimbus
