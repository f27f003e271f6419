#pragma once
// One light per vertex for next-event estimation (integrator.light_sampling "one"): light i is
// picked at p with probability proportional to its unoccluded fluence there, ∫ L dω over the
// directions it covers, at the path's channels (their average):
//   environment 4π L, directional E, point I / d², sphere L · 2π (1 − cos θ_max) (4π L inside).
// A shadow ray costs the same whichever light it aims at, so the light that can bring the most
// gets the most rays; in a dense medium that is most of a vertex's cost (docs/benchmarks.md,
// "Light sampling"). The contribution is divided by the probability and MIS takes it into the
// light technique's pdf. That stays unbiased: a light only light sampling can reach (directional,
// point) has a positive probability wherever it emits, and a light given probability 0 (a sky,
// light_choice_weight) is found by phase and BSDF sampling with MIS weight 1.

#include <algorithm>
#include <cmath>
#include <utility>

#include "nimbus/math/constants.h"
#include "nimbus/render/light.h"
#include "nimbus/render/light_tree.h"
#include "nimbus/render/path_spectra.h"
#include "nimbus/render/scene.h"

namespace nimbus {

// The unoccluded fluence of `light`, whose emission at the path's channels is `emission`, at p
// (light.h).
template <int N>
double light_fluence(const Light& light, const Spectrum<N>& emission, const Vec3& p) {
  return light_fluence(light, std::max(0.0, emission.average()), p);
}

// The weight with which light j is picked at p: its fluence there, but 0 for a constant
// environment when another light has fluence at p. BSDF and phase sampling already draw
// directions in proportion to what multiplies a constant sky's radiance, so MIS gives such
// samples the sky (a picked light's pdf of 0 gives them weight 1), and the shadow rays go to the
// lights only light sampling finds: the sun, points, spheres. pbrt-v4 does the same (its uniform
// infinite light gives no sample where the pdf may be incomplete).
template <int N>
double light_choice_weight(const Scene& scene, const PathSpectra<N>& ps, int j, const Vec3& p,
                           bool skip_environment) {
  const Light& light = scene.lights[j];
  if (skip_environment && at_infinity(light)) return 0;
  return light_fluence(light, light_emission(ps, scene, j), p);
}

// With a light tree (many positioned lights, light_tree.h), the choice weighs the lights
// outside it (sky, suns) as above and the tree as one more candidate whose weight is its root's
// importance at p, then descends the tree. `others` is the sum of the outside lights' weights.
struct TreeChoice {
  double others = 0, tree = 0, total = 0;
  bool skip = true;  // a constant environment gets weight 0
};

template <int N>
TreeChoice tree_choice(const Scene& scene, const PathSpectra<N>& ps, const Vec3& p) {
  TreeChoice c;
  c.tree = light_node_importance(scene.light_tree.nodes[0], p);
  for (const int j : scene.light_tree.others)
    c.others += light_choice_weight(scene, ps, j, p, true);
  c.total = c.others + c.tree;
  if (c.total > 0 && std::isfinite(c.total)) return c;
  c.skip = false;
  c.others = 0;
  for (const int j : scene.light_tree.others)
    c.others += light_choice_weight(scene, ps, j, p, false);
  c.total = c.others + c.tree;
  return c;
}

// The sum of the weights, with the choice whether to skip environments.
template <int N>
std::pair<double, bool> light_choice_total(const Scene& scene, const PathSpectra<N>& ps,
                                           const Vec3& p) {
  const int n = static_cast<int>(scene.lights.size());
  double total = 0;
  for (int j = 0; j < n; ++j) total += light_choice_weight(scene, ps, j, p, true);
  if (total > 0 && std::isfinite(total)) return {total, true};
  total = 0;
  for (int j = 0; j < n; ++j) total += light_choice_weight(scene, ps, j, p, false);
  return {total, false};
}

// The probability with which choose_light picks light i at p.
template <int N>
double light_choice_pdf(const Scene& scene, const PathSpectra<N>& ps, int i, const Vec3& p) {
  if (!scene.light_tree.nodes.empty()) {
    const TreeChoice c = tree_choice(scene, ps, p);
    if (!(c.total > 0) || !std::isfinite(c.total)) return 1.0 / double(scene.lights.size());
    if (scene.light_tree.depth[size_t(i)] < 0)
      return light_choice_weight(scene, ps, i, p, c.skip) / c.total;
    return c.tree / c.total * light_tree_pdf(scene.light_tree, i, p);
  }
  const auto [total, skip] = light_choice_total(scene, ps, p);
  if (!(total > 0) || !std::isfinite(total)) return 1.0 / double(scene.lights.size());
  return light_choice_weight(scene, ps, i, p, skip) / total;
}

// A light picked at p from u uniform in [0, 1), and the probability it was picked with (> 0).
template <int N>
std::pair<int, double> choose_light(const Scene& scene, const PathSpectra<N>& ps, const Vec3& p,
                                    double u) {
  const int n = static_cast<int>(scene.lights.size());
  if (!scene.light_tree.nodes.empty()) {
    const TreeChoice c = tree_choice(scene, ps, p);
    if (!(c.total > 0) || !std::isfinite(c.total)) {
      const int i = std::min(n - 1, static_cast<int>(u * n));
      return {i, 1.0 / n};
    }
    double below = 0;
    for (const int j : scene.light_tree.others) {
      const double w = light_choice_weight(scene, ps, j, p, c.skip);
      if (w > 0 && u * c.total < below + w) return {j, w / c.total};
      below += w;
    }
    // The rest of [0, 1) is the tree's: u rescaled into [0, 1) for the descent.
    const double v = std::clamp((u * c.total - below) / c.tree, 0.0, 0x1.fffffffffffffp-1);
    const auto [j, pdf] = descend_light_tree(scene.light_tree, p, v);
    return {j, c.tree / c.total * pdf};
  }
  const auto [total, skip] = light_choice_total(scene, ps, p);
  if (!(total > 0) || !std::isfinite(total)) {
    const int i = std::min(n - 1, static_cast<int>(u * n));
    return {i, 1.0 / n};
  }
  // The last light with positive weight takes what rounding leaves at the top.
  double below = 0;
  int last = 0;
  for (int j = 0; j < n; ++j) {
    const double w = light_choice_weight(scene, ps, j, p, skip);
    if (!(w > 0)) continue;
    last = j;
    if (u * total < below + w) return {j, w / total};
    below += w;
  }
  return {last, light_choice_weight(scene, ps, last, p, skip) / total};
}

}  // namespace nimbus
