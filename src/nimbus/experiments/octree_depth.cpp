#include "nimbus/experiments/octree_depth.h"

#include <fmt/format.h>

#include <algorithm>

#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace nimbus {
namespace {

struct Row {
  int depth;
  double build_seconds;
  size_t nodes, bytes;
  int depth_reached;
  double render_seconds, lookups_per_sample, segments_per_sample, null_fraction,
      lookups_per_real_collision;
};

}  // namespace

ExperimentReport run_octree_depth(const ExperimentOptions& options) {
  const std::vector<int> depths =
      options.quick ? std::vector<int>{0, 2, 4} : std::vector<int>{0, 1, 2, 4, 8, 12, 16};
  const int spp = options.quick ? 1 : 4, repeat = options.quick ? 1 : 3;
  std::vector<std::string> overrides = {fmt::format("integrator.spp={}", spp),
                                        fmt::format("integrator.seed={}", options.seed),
                                        "integrator.tracking=delta",
                                        // as docs/reproduction.md describes the experiment
                                        "integrator.transmittance=ratio"};
  if (options.quick) overrides.insert(overrides.end(), {"film.width=32", "film.height=20"});
  const std::string file = (options.scenes / "bench" / "cloud_octree.json").string();
  RenderOptions render_options;
  render_options.threads = options.threads;

  std::vector<Row> rows;
  std::string summary;
  for (int depth : depths) {
    std::vector<std::string> with_depth = overrides;
    with_depth.push_back(fmt::format("integrator.octree.depth={}", depth));
    const SceneDesc desc = load_scene_file(file, with_depth);
    Scene scene = compile_scene(desc);
    RenderResult r = render(scene, render_options);
    double build_seconds = scene.field_octree.build_seconds, render_seconds = r.seconds;
    for (int i = 1; i < repeat; ++i) {
      scene = compile_scene(desc);
      r = render(scene, render_options);
      build_seconds = std::min(build_seconds, scene.field_octree.build_seconds);
      render_seconds = std::min(render_seconds, r.seconds);
    }
    const Counters& c = r.counters;
    const double samples = double(scene.settings.width) * scene.settings.height * spp;
    const Row row{depth,
                  build_seconds,
                  scene.field_octree.nodes.size(),
                  scene.field_octree.bytes(),
                  scene.field_octree.depth,
                  render_seconds,
                  double(c.tracking.lookups) / samples,
                  double(c.majorant_segments) / samples,
                  double(c.null_collisions()) / double(c.tracking.tentative_collisions),
                  double(c.tracking.lookups) / double(c.real_collisions)};
    summary += fmt::format(
        "  depth {:2}: build {:.3f} s, {} nodes, {:.1f} MiB, reached {}, render {:.2f} s, "
        "{:.1f} lookups/sample, {:.1f} segments/sample, null fraction {:.3f}\n",
        depth, row.build_seconds, row.nodes, double(row.bytes) / 1048576.0, row.depth_reached,
        row.render_seconds, row.lookups_per_sample, row.segments_per_sample, row.null_fraction);
    rows.push_back(row);
  }
  // Relative columns against depth 1, as the paper's Table 2, when depth 1 was run.
  const auto base =
      std::find_if(rows.begin(), rows.end(), [](const Row& row) { return row.depth == 1; });
  const bool has_base = base != rows.end();
  std::string csv =
      "depth,build_seconds,nodes,bytes,depth_reached,render_seconds,lookups_per_sample,"
      "segments_per_sample,null_fraction,lookups_per_real_collision,render_time_vs_depth1,"
      "lookups_vs_depth1\n";
  for (const Row& row : rows)
    csv += fmt::format("{},{:.4f},{},{},{},{:.3f},{:.2f},{:.2f},{:.4f},{:.2f},{:.3f},{:.3f}\n",
                       row.depth, row.build_seconds, row.nodes, row.bytes, row.depth_reached,
                       row.render_seconds, row.lookups_per_sample, row.segments_per_sample,
                       row.null_fraction, row.lookups_per_real_collision,
                       has_base ? row.render_seconds / base->render_seconds : 0.0,
                       has_base ? row.lookups_per_sample / base->lookups_per_sample : 0.0);
  return {{write_text(options.out, "octree_depth.csv", csv)}, summary};
}

}  // namespace nimbus
