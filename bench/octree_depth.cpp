// The paper's Table 2 / Fig. 7 experiment: octree depth against build time, memory and tracking
// cost. Renders a scene at each depth with the same samples and seed and writes one CSV row per
// depth; tools/plot_octree_depth.py draws it.
//
//   octree_depth SCENE OUT.csv [--spp N] [--threads N] [--repeat N] [--depths 0,1,2,4,8,12,16]
//
// With --repeat, each depth is built and rendered N times and the shortest times are kept: on a
// shared machine the least disturbed run is the best estimate (the counters are identical).

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace {

struct Row {
  int depth;
  double build_seconds;
  size_t nodes, bytes;
  int depth_reached;
  double render_seconds, lookups_per_sample, segments_per_sample, null_fraction,
      lookups_per_real_collision;
};

std::vector<int> parse_depths(const std::string& list) {
  std::vector<int> depths;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');) depths.push_back(std::stoi(item));
  return depths;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: octree_depth SCENE OUT.csv [--spp N] [--threads N] [--repeat N] "
                 "[--depths LIST]\n";
    return 2;
  }
  const std::string scene_path = argv[1], csv_path = argv[2];
  int spp = 4, threads = 0, repeat = 1;
  std::vector<int> depths{0, 1, 2, 4, 8, 12, 16};
  for (int i = 3; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--spp")
      spp = std::stoi(value);
    else if (key == "--threads")
      threads = std::stoi(value);
    else if (key == "--repeat")
      repeat = std::max(1, std::stoi(value));
    else if (key == "--depths")
      depths = parse_depths(value);
    else {
      std::cerr << "unknown option " << key << "\n";
      return 2;
    }
  }
  std::vector<Row> rows;
  for (int depth : depths) {
    const nimbus::SceneDesc desc = nimbus::load_scene_file(
        scene_path,
        {fmt::format("integrator.octree.depth={}", depth), fmt::format("integrator.spp={}", spp)});
    nimbus::Scene scene = nimbus::compile_scene(desc);
    nimbus::RenderResult r = nimbus::render(scene, {threads, {}});
    double build_seconds = scene.field_octree.build_seconds, render_seconds = r.seconds;
    for (int i = 1; i < repeat; ++i) {
      scene = nimbus::compile_scene(desc);
      r = nimbus::render(scene, {threads, {}});
      build_seconds = std::min(build_seconds, scene.field_octree.build_seconds);
      render_seconds = std::min(render_seconds, r.seconds);
    }
    const nimbus::Counters& c = r.counters;
    const double samples = double(scene.settings.width) * scene.settings.height * spp;
    Row row{depth,
            build_seconds,
            scene.field_octree.nodes.size(),
            scene.field_octree.bytes(),
            scene.field_octree.depth,
            render_seconds,
            double(c.tracking.lookups) / samples,
            double(c.majorant_segments) / samples,
            double(c.null_collisions()) / double(c.tracking.tentative_collisions),
            double(c.tracking.lookups) / double(c.real_collisions)};
    std::cerr << fmt::format(
        "depth {:2}: build {:.3f} s, {} nodes, {:.1f} MiB, reached {}, render {:.2f} s, "
        "{:.1f} lookups/sample, {:.1f} segments/sample, null fraction {:.3f}\n",
        depth, row.build_seconds, row.nodes, row.bytes / 1048576.0, row.depth_reached,
        row.render_seconds, row.lookups_per_sample, row.segments_per_sample, row.null_fraction);
    rows.push_back(row);
  }
  // Relative columns against depth 1, as the paper's Table 2, when depth 1 was run.
  const Row* base = nullptr;
  for (const Row& row : rows)
    if (row.depth == 1) base = &row;
  std::ofstream out(csv_path);
  out << "depth,build_seconds,nodes,bytes,depth_reached,render_seconds,lookups_per_sample,"
         "segments_per_sample,null_fraction,lookups_per_real_collision,render_time_vs_depth1,"
         "lookups_vs_depth1\n";
  for (const Row& row : rows)
    out << fmt::format("{},{:.4f},{},{},{},{:.3f},{:.2f},{:.2f},{:.4f},{:.2f},{:.3f},{:.3f}\n",
                       row.depth, row.build_seconds, row.nodes, row.bytes, row.depth_reached,
                       row.render_seconds, row.lookups_per_sample, row.segments_per_sample,
                       row.null_fraction, row.lookups_per_real_collision,
                       base ? row.render_seconds / base->render_seconds : 0.0,
                       base ? row.lookups_per_sample / base->lookups_per_sample : 0.0);
  return out ? 0 : 1;
}
