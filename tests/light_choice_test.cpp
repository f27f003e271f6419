// Picking one light per vertex (render/light_choice.h): probabilities proportional to each
// light's unoccluded fluence (a constant sky left out while another light shines), and a pick
// that follows them.

#include "nimbus/render/light_choice.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "nimbus/math/constants.h"
#include "nimbus/math/rng.h"
#include "support/stats.h"

namespace nimbus {
namespace light_choice_test {

struct Lights {
  Scene scene;
  PathSpectra<3> ps;

  void add(Light light, const Rgb& emission) {
    light.emission = emission;
    scene.lights.push_back(light);
    ps.lights.push_back(emission);
  }
};

Lights four_lights() {
  Lights l;
  Light env, sun, bulb, ball;
  env.type = Light::Type::Environment;
  sun.type = Light::Type::Directional;
  sun.direction = {0, -1, 0};
  bulb.type = Light::Type::Point;
  bulb.position = {0, 2, 0};
  ball.type = Light::Type::Sphere;
  ball.center = {3, 0, 0};
  ball.radius = 1;
  l.add(env, Rgb({0.1, 0.2, 0.3}));
  l.add(sun, Rgb(2.0));
  l.add(bulb, Rgb({4.0, 8.0, 0.0}));
  l.add(ball, Rgb(1.5));
  return l;
}

TEST(LightChoice, FluenceOfEachKind) {
  const Lights l = four_lights();
  const Vec3 p{0, 0, 0};
  EXPECT_DOUBLE_EQ(light_fluence(l.scene.lights[0], l.ps.lights[0], p), 4 * kPi * 0.2);
  EXPECT_DOUBLE_EQ(light_fluence(l.scene.lights[1], l.ps.lights[1], p), 2.0);
  EXPECT_DOUBLE_EQ(light_fluence(l.scene.lights[2], l.ps.lights[2], p), 4.0 / 4);
  // A sphere of radius 1 at distance 3: solid angle 2π (1 − cos θ), sin θ = 1/3.
  EXPECT_NEAR(light_fluence(l.scene.lights[3], l.ps.lights[3], p),
              1.5 * 2 * kPi * (1 - std::sqrt(1 - 1.0 / 9)), 1e-12);
  // Inside the sphere it fills every direction.
  EXPECT_DOUBLE_EQ(light_fluence(l.scene.lights[3], l.ps.lights[3], Vec3{3, 0.5, 0}),
                   1.5 * 4 * kPi);
}

TEST(LightChoice, PicksFollowTheProbabilities) {
  const Lights l = four_lights();
  for (const Vec3& p : {Vec3{0, 0, 0}, Vec3{2.5, 1, 0}, Vec3{-4, 0.1, 7}}) {
    const int n = 4;
    std::vector<double> pdf(n);
    double total = 0;
    for (int i = 0; i < n; ++i) total += pdf[i] = light_choice_pdf(l.scene, l.ps, i, p);
    EXPECT_NEAR(total, 1, 1e-12);
    const int draws = 100000;
    std::vector<int> count(n, 0);
    Rng rng(41);
    for (int k = 0; k < draws; ++k) {
      const auto [i, q] = choose_light(l.scene, l.ps, p, rng.uniform());
      ASSERT_DOUBLE_EQ(q, pdf[i]);
      ++count[i];
    }
    double chi2 = 0;
    int cells = 0;
    for (int i = 0; i < n; ++i) {
      if (pdf[i] == 0) {
        EXPECT_EQ(count[i], 0) << i;
        continue;
      }
      const double expected = draws * pdf[i];
      chi2 += (count[i] - expected) * (count[i] - expected) / expected;
      ++cells;
    }
    ASSERT_GE(cells, 2);
    EXPECT_LT(chi2, test::chi_square_critical(cells - 1, 1e-4));
  }
}

// Issue 26: with many positioned lights the pick descends a light tree (light_tree.h). The
// probabilities sum to 1, choose_light reports what light_choice_pdf says, the draws follow
// them (chi-square), and every light with power has a positive probability everywhere.
TEST(LightChoice, TheLightTreePicksFollowTheProbabilities) {
  Lights l;
  Light env, sun;
  env.type = Light::Type::Environment;
  sun.type = Light::Type::Directional;
  sun.direction = {0, -1, 0};
  l.add(env, Rgb(0.2));
  l.add(sun, Rgb(0.5));
  Rng place(3);
  for (int k = 0; k < 62; ++k) {
    Light light;
    light.type = k % 2 ? Light::Type::Point : Light::Type::Sphere;
    light.position =
        light.center = {6 * place.uniform() - 3, 3 * place.uniform(), 6 * place.uniform() - 3};
    light.radius = 0.05 + 0.2 * place.uniform();
    l.add(light, Rgb({place.uniform(), 2 * place.uniform(), 0.5}));
  }
  l.scene.light_tree = build_light_tree(l.scene.lights);
  ASSERT_FALSE(l.scene.light_tree.nodes.empty());
  const int n = int(l.scene.lights.size());
  for (const Vec3& p : {Vec3{0, 0, 0}, Vec3{2.5, 1, 0}, Vec3{-40, 0.1, 70}}) {
    std::vector<double> pdf(n);
    double total = 0;
    for (int i = 0; i < n; ++i) total += pdf[i] = light_choice_pdf(l.scene, l.ps, i, p);
    EXPECT_NEAR(total, 1, 1e-12);
    EXPECT_EQ(pdf[0], 0);  // the sky is left to BSDF sampling while the others shine
    for (int i = 1; i < n; ++i) EXPECT_GT(pdf[i], 0) << i;
    const int draws = 200000;
    std::vector<int> count(n, 0);
    Rng rng(43);
    for (int k = 0; k < draws; ++k) {
      const auto [i, q] = choose_light(l.scene, l.ps, p, rng.uniform());
      ASSERT_NEAR(q, pdf[i], 1e-12 * pdf[i]) << i;
      ++count[i];
    }
    // Cells of at least 5 expected draws; the rest pooled.
    double chi2 = 0, pooled_expected = 0;
    int cells = 0, pooled = 0;
    for (int i = 0; i < n; ++i) {
      const double expected = draws * pdf[i];
      if (expected < 5) {
        pooled_expected += expected;
        pooled += count[i];
        continue;
      }
      chi2 += (count[i] - expected) * (count[i] - expected) / expected;
      ++cells;
    }
    if (pooled_expected >= 5) {
      chi2 += (pooled - pooled_expected) * (pooled - pooled_expected) / pooled_expected;
      ++cells;
    }
    ASSERT_GE(cells, 10);
    EXPECT_LT(chi2, test::chi_square_critical(cells - 1, 1e-4));
  }
}

// A constant sky is left to BSDF and phase sampling while another light has fluence; alone, it
// is picked.
TEST(LightChoice, EnvironmentOnlyWhenAlone) {
  Lights l = four_lights();
  EXPECT_EQ(light_choice_pdf(l.scene, l.ps, 0, Vec3{0, 0, 0}), 0.0);
  EXPECT_NEAR(light_choice_pdf(l.scene, l.ps, 1, Vec3{0, 0, 0}),
              2.0 / (2.0 + 1.0 + 1.5 * 2 * kPi * (1 - std::sqrt(1 - 1.0 / 9))), 1e-12);
  for (int j = 1; j < 4; ++j) l.ps.lights[j] = Rgb(0.0);
  EXPECT_EQ(light_choice_pdf(l.scene, l.ps, 0, Vec3{0, 0, 0}), 1.0);
  EXPECT_EQ(choose_light(l.scene, l.ps, Vec3{0, 0, 0}, 0.7).first, 0);
}

// Lights with no emission at the path's channels are never picked; when none has any, the pick
// is uniform.
TEST(LightChoice, DarkLights) {
  Lights l = four_lights();
  l.ps.lights[1] = Rgb(0.0);
  EXPECT_EQ(light_choice_pdf(l.scene, l.ps, 1, Vec3{0, 0, 0}), 0.0);
  for (double u : {0.0, 0.3, 0.6, 0.999999})
    EXPECT_NE(choose_light(l.scene, l.ps, Vec3{0, 0, 0}, u).first, 1);
  for (Spectrum<3>& e : l.ps.lights) e = Rgb(0.0);
  for (int i = 0; i < 4; ++i)
    EXPECT_DOUBLE_EQ(light_choice_pdf(l.scene, l.ps, i, Vec3{0, 0, 0}), 0.25);
  EXPECT_EQ(choose_light(l.scene, l.ps, Vec3{0, 0, 0}, 0.6).first, 2);
}

}  // namespace light_choice_test
}  // namespace nimbus
