// Issue 26: thousands of lights picked through the light tree render the right image. A diffuse
// floor of albedo ρ is lit by 3 000 point lights, 16 sphere lights and a sun, and seen from
// just above it by an orthographic camera under the lights: each point x of the floor reflects
// L(x) = ρ/π (Σ I cos θ / d² + Σ π L_s (r/d)² cos θ + E cos θ_sun), the spheres' term exact for
// a sphere wholly above the horizon. The image mean must match that averaged over the view
// (midpoint rule), within the render's own standard error; next-event estimation picks one light
// a vertex through the tree, and BSDF samples that hit a sphere light are weighed by MIS with
// the tree's probabilities.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "nimbus/math/constants.h"
#include "nimbus/math/rng.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace nimbus {
namespace light_tree_render_test {

TEST(LightTree, ThousandsOfLightsRenderTheClosedForm) {
  constexpr double kAlbedo = 0.5, kHalf = 1.0;  // the view: x, z in [-1, 1]
  Rng rng(17, 5);
  struct Source {
    Vec3 c;
    double r, emission;  // r = 0: a point light of intensity `emission`
  };
  std::vector<Source> sources;
  std::string lights = R"({"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": 0.5})";
  // Point lights do not block one another; the sphere lights hang above them on a grid of
  // spacing 2, where no shadow ray to one passes near another.
  for (int k = 0; k < 3000 + 16; ++k) {
    const bool sphere = k >= 3000;
    const Vec3 c =
        sphere ? Vec3{2.0 * (k % 4) - 3, 3, 2.0 * ((k - 3000) / 4) - 3}
               : Vec3{8 * rng.uniform() - 4, 0.5 + 1.5 * rng.uniform(), 8 * rng.uniform() - 4};
    const double r = sphere ? 0.05 : 0.0;
    const double e =
        sphere ? (0.5 + rng.uniform()) / 4 / (kPi * r * r) : (0.5 + rng.uniform()) / 300;
    sources.push_back({c, r, e});
    lights += sphere
                  ? fmt::format(R"(, {{"type": "sphere", "center": [{:.17g}, {:.17g}, {:.17g}], )"
                                R"("radius": {:.17g}, "radiance": {:.17g}}})",
                                c.x, c.y, c.z, r, e)
                  : fmt::format(R"(, {{"type": "point", "position": [{:.17g}, {:.17g}, {:.17g}], )"
                                R"("intensity": {:.17g}}})",
                                c.x, c.y, c.z, e);
  }
  const std::string text = fmt::format(R"({{
    "film": {{"width": 16, "height": 16}},
    "camera": {{"type": "orthographic", "from": [0, 0.1, 0], "to": [0, 0, 0], "up": [0, 0, 1],
                "width": {}}},
    "integrator": {{"spp": 64, "seed": 5, "sampler": "independent"}},
    "lights": [{}],
    "shapes": {{"floor": {{"type": "box", "min": [-9, -1, -9], "max": [9, 0, 9]}}}},
    "objects": [{{"shape": "floor", "surface": {{"type": "diffuse", "albedo": {}}}}}]
  }})",
                                       2 * kHalf, lights, kAlbedo);
  const Scene scene = compile_scene(load_scene_text(text, "lights.json"));
  ASSERT_FALSE(scene.light_tree.nodes.empty());
  RenderOptions options;
  options.threads = 2;
  const RenderResult r = render(scene, options);
  const MeanEstimate m = image_mean(r.film);

  // The closed form averaged over the view, 120 x 120 midpoints.
  const Vec3 sun = normalize(Vec3{-0.3, 1, -0.2});
  const int grid = 120;
  double sum = 0;
  for (int i = 0; i < grid; ++i)
    for (int j = 0; j < grid; ++j) {
      const Vec3 x{kHalf * (2 * (i + 0.5) / grid - 1), 0, kHalf * (2 * (j + 0.5) / grid - 1)};
      double E = 0.5 * sun.y;
      for (const Source& s : sources) {
        const Vec3 d = s.c - x;
        const double d2 = dot(d, d), cos_theta = d.y / std::sqrt(d2);
        E += s.r > 0 ? kPi * s.emission * s.r * s.r / d2 * cos_theta : s.emission * cos_theta / d2;
      }
      sum += kAlbedo / kPi * E;
    }
  const double expected = sum / (grid * grid);
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(std::abs(m.mean[c] - expected), 4 * m.standard_error[c])
        << "channel " << c << ": " << m.mean[c] << " against " << expected << " (standard error "
        << m.standard_error[c] << ")";
    EXPECT_LT(m.standard_error[c], 0.02 * expected);  // a test with power
  }
}

}  // namespace light_tree_render_test
}  // namespace nimbus
