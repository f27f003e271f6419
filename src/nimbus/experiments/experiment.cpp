#include "nimbus/experiments/experiment.h"

#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include <fstream>

#include "nimbus/experiments/figures.h"
#include "nimbus/experiments/octree_depth.h"
#include "nimbus/experiments/scatter_distance.h"
#include "nimbus/experiments/segments.h"
#include "nimbus/experiments/throughput.h"
#include "nimbus/io/atomic_file.h"

namespace nimbus {

const std::vector<Experiment>& experiments() {
  static const std::vector<Experiment> all = {
      {"figures", "Figs. 1-3: renders scenes/freeforms, translucent and cloud.json", run_figures},
      {"throughput", "Figs. 4-5: RGB path throughput against distance, max vs. history-aware rule",
       run_throughput},
      {"scatter-distance", "Fig. 6: density of distances between scattering events",
       run_scatter_distance},
      {"segments",
       "Sec. 4: path segments, lookups and equal-time MSE of spectral vs. delta tracking",
       run_segments},
      {"octree-depth",
       "Table 2, Fig. 7: octree build time, memory and tracking work against octree depth",
       run_octree_depth},
  };
  return all;
}

std::filesystem::path write_text(const std::filesystem::path& dir, const std::string& name,
                                 const std::string& text) {
  const std::filesystem::path path = dir / name;
  write_atomically(path.string(), [&](const std::string& tmp) {
    std::ofstream f(tmp);
    f << text;
    if (!f) throw std::runtime_error("cannot write");
  });
  return path;
}

void parallel_for_index(int n, int threads, const std::function<void(int)>& body) {
  const int t = threads > 0 ? threads : tbb::info::default_concurrency();
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, t);
  tbb::parallel_for(0, n, [&](int i) { body(i); });
}

}  // namespace nimbus
