#include "nimbus/render/stats.h"

#include <algorithm>
#include <numeric>

#include "nimbus/render/noise_target.h"
#include "nimbus/render/settings.h"

namespace nimbus {

nlohmann::json render_stats(const Scene& scene, const RenderResult& result,
                            const std::string& scene_path, std::uint64_t samples_rendered) {
  const Counters& c = result.counters;
  const double samples = double(samples_rendered);
  const MeanEstimate m = image_mean(result.film);
  nlohmann::json j;
  j["scene"] = scene_path;
  j["threads"] = result.threads;
  // Every setting rendered with, by its scene-file key (render/settings.h).
  j["settings"] = settings_json(scene.settings);
  j["channels"] = scene.settings.spectral.mode == SpectralSettings::Mode::Spectral
                      ? scene.settings.spectral.wavelengths
                      : 3;
  j["wall_seconds"] = result.seconds;
  j["samples"] = samples_rendered;
  j["samples_per_second"] = result.seconds > 0 ? samples / result.seconds : 0.0;
  j["image_mean"] = {m.mean[0], m.mean[1], m.mean[2]};
  j["image_mean_standard_error"] = {m.standard_error[0], m.standard_error[1], m.standard_error[2]};
  j["counters"] = {
      {"paths", c.paths},
      {"rejected_samples", c.rejected_samples},
      {"surface_rays", c.surface_rays},
      {"shadow_rays", c.shadow_rays},
      {"path_segments", c.tracking.tentative_collisions},
      {"density_lookups", c.tracking.lookups},
      {"shadow_ray_lookups", c.shadow_lookups},
      {"real_collisions", c.real_collisions},
      {"null_collisions", c.null_collisions()},
      {"scatter_events", c.scatter_events},
      {"majorant_segments", c.majorant_segments},
      {"mean_scatter_events_per_path", c.paths ? double(c.scatter_events) / c.paths : 0.0},
      {"clamped_probabilities", c.tracking.clamped},
      {"raised_majorants", c.tracking.raised},
      {"null_collision_fraction",
       c.tracking.tentative_collisions
           ? double(c.null_collisions()) / double(c.tracking.tentative_collisions)
           : 0.0},
      {"density_lookups_per_real_collision",
       c.real_collisions ? double(c.tracking.lookups) / double(c.real_collisions) : 0.0},
      {"density_lookups_per_sample", samples > 0 ? double(c.tracking.lookups) / samples : 0.0},
      {"manifold_walks", c.manifold.walks},
      {"manifold_successes", c.manifold.found},
      {"manifold_mean_newton_steps",
       c.manifold.walks ? double(c.manifold.newton_steps) / double(c.manifold.walks) : 0.0},
      {"manifold_checks", c.manifold.checks},
      {"mirror_probes", c.manifold.mirror_probes},
  };
  // All octrees together: the field's and those inside solids.
  double build_seconds = 0;
  size_t nodes = 0, built_nodes = 0, bytes = 0;
  uint64_t sampled = 0;
  int depth = 0;
  auto add = [&](const MajorantOctree& t) {
    build_seconds += t.build_seconds;
    sampled += t.sampled_points;
    nodes += t.nodes.size();
    built_nodes += t.built_nodes;
    bytes += t.nodes.empty() ? 0 : t.bytes();
    depth = std::max(depth, t.depth);
  };
  add(scene.field_octree);
  for (const MajorantOctree& t : scene.solid_octrees.trees) add(t);
  j["octree"] = {{"build_seconds", build_seconds},
                 {"nodes", nodes},
                 {"built_nodes", built_nodes},
                 {"bytes", bytes},
                 {"depth_requested", scene.settings.tracking.octree_depth},
                 {"depth", depth},
                 {"sampled_points", sampled}};
  if (const NoiseRule rule = noise_rule(scene.settings); rule.on()) {
    const NoiseProgress p = noise_progress(rule, result.film);
    j["noise_target"] = {
        {"target", rule.target},
        {"min_spp", rule.min_spp},
        {"pixels_done", p.converged},
        {"pixels_at_cap_above_target", p.capped},
        {"mean_spp", std::accumulate(result.film.samples.begin(), result.film.samples.end(), 0.0) /
                         std::max(1, result.film.pixels())},
        {"max_spp", result.film.most_samples()}};
  }
  return j;
}

}  // namespace nimbus
