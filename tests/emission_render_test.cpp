// Emission in media (eq. 4's mu_a L_e term): a homogeneous emitting absorber in front of a
// uniform environment.

#include <gtest/gtest.h>

#include <cmath>

#include "nimbus/frep/primitives.h"
#include "nimbus/render/renderer.h"
#include "support/scene_builders.h"
#include "support/stats.h"

namespace nimbus {
namespace {

TEST(EmissionRender, EmittingAbsorberMatchesClosedForm) {
  const Rgb sigma_a({1.0, 2.0, 0.5}), L_e({2.0, 1.0, 3.0});
  const double background = 0.5, view = 2.2;
  const int size = 16;
  Scene scene;
  scene.settings = {size, size, 1024, 13, 100, {}};
  scene.camera = orthographic_camera({0, 0, 4}, {0, 0, 0}, {0, 1, 0}, view, size, size);
  scene.lights.push_back(test::environment(background));
  Medium fire;
  fire.sigma_a = sigma_a;
  fire.emission = L_e;
  scene.media.push_back(fire);
  scene.objects.push_back(
      test::object_of(make_shape(QuadricNode{sphere({0, 0, 0}, 1)}), Surface::Type::None, 0));
  test::finish_media(scene);
  const RenderResult r = render(scene);

  // Along a chord of length ℓ: L = L_e (1 − e^{−σ_a ℓ}) + background e^{−σ_a ℓ}, averaged over
  // each pixel's footprint.
  double chi2 = 0;
  int dof = 0;
  const double px = view / size;
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
            const double b2 = sx * sx + sy * sy;
            const double T = b2 >= 1 ? 1.0 : std::exp(-sigma_a[c] * 2 * std::sqrt(1 - b2));
            ref += L_e[c] * (1 - T) + background * T;
          }
        ref /= k * k;
        const double var = r.film.variance_of_mean(p)[c];
        if (var <= 0) {
          EXPECT_NEAR(r.film.mean(p)[c], ref, 1e-3) << p;
          continue;
        }
        const double z = (r.film.mean(p)[c] - ref) / std::sqrt(var);
        chi2 += z * z;
        ++dof;
      }
    }
  ASSERT_GT(dof, 200);
  EXPECT_LT(chi2, test::chi_square_critical(dof, 1e-4)) << "over " << dof << " pixel-channels";
}

}  // namespace
}  // namespace nimbus
