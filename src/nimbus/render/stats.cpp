#include "nimbus/render/stats.h"

namespace nimbus {

nlohmann::json render_stats(const Scene& scene, const RenderResult& result,
                            const std::string& scene_path) {
  const Counters& c = result.counters;
  const double samples = double(scene.settings.width) * scene.settings.height * scene.settings.spp;
  const MeanEstimate m = image_mean(result.film);
  nlohmann::json j;
  j["scene"] = scene_path;
  j["width"] = scene.settings.width;
  j["height"] = scene.settings.height;
  j["spp"] = scene.settings.spp;
  j["seed"] = scene.settings.seed;
  j["threads"] = result.threads;
  j["wall_seconds"] = result.seconds;
  j["samples_per_second"] = result.seconds > 0 ? samples / result.seconds : 0.0;
  j["image_mean"] = {m.mean[0], m.mean[1], m.mean[2]};
  j["image_mean_standard_error"] = {m.standard_error[0], m.standard_error[1], m.standard_error[2]};
  j["counters"] = {
      {"paths", c.paths},
      {"surface_rays", c.surface_rays},
      {"shadow_rays", c.shadow_rays},
      {"path_segments", c.tracking.tentative_collisions},
      {"density_lookups", c.tracking.lookups},
      {"real_collisions", c.real_collisions},
      {"null_collisions", c.null_collisions()},
      {"scatter_events", c.scatter_events},
      {"mean_scatter_events_per_path", c.paths ? double(c.scatter_events) / c.paths : 0.0},
      {"clamped_probabilities", c.tracking.clamped},
  };
  return j;
}

}  // namespace nimbus
