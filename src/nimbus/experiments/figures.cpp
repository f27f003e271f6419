#include "nimbus/experiments/figures.h"

#include <fmt/format.h>

#include <array>

#include "nimbus/io/film_image.h"
#include "nimbus/io/output.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace nimbus {

ExperimentReport run_figures(const ExperimentOptions& options) {
  const std::array<const char*, 3> scenes = {"freeforms", "translucent", "cloud"};
  ExperimentReport report;
  std::string csv = "figure,scene,width,height,spp,seconds,mean_r,mean_g,mean_b\n";
  for (int k = 0; k < int(scenes.size()); ++k) {
    std::vector<std::string> overrides = {fmt::format("integrator.seed={}", options.seed),
                                          "integrator.tracking=spectral-history"};
    if (options.quick)
      overrides.insert(overrides.end(), {"film.width=48", "film.height=32", "integrator.spp=1"});
    const Scene scene = compile_scene(
        load_scene_file((options.scenes / (std::string(scenes[k]) + ".json")).string(), overrides));
    RenderOptions render_options;
    render_options.threads = options.threads;
    const RenderResult r = render(scene, render_options);
    const Image image = to_image(r.film);
    const std::string stem = fmt::format("fig{}_{}", k + 1, scenes[k]);
    for (const char* ext : {".exr", ".png"}) {
      report.files.push_back(options.out / (stem + ext));
      write_image(report.files.back().string(), image);
    }
    const MeanEstimate m = image_mean(r.film);
    const RenderSettings& s = scene.settings;
    csv += fmt::format("{},{},{},{},{},{:.3f},{:.6g},{:.6g},{:.6g}\n", k + 1, scenes[k], s.width,
                       s.height, s.spp, r.seconds, m.mean[0], m.mean[1], m.mean[2]);
    report.summary += fmt::format("  Fig. {} {:12} {}x{} at {} spp in {:.2f} s -> {}.png\n", k + 1,
                                  scenes[k], s.width, s.height, s.spp, r.seconds, stem);
  }
  report.files.insert(report.files.begin(), write_text(options.out, "figures.csv", csv));
  return report;
}

}  // namespace nimbus
