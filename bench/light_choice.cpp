// The light tree against the per-light choice at equal time (issue 26): N sphere lights on a
// grid over a diffuse floor (the scene of tools/bench_scale.py lights), each rendered with the
// light tree (the default from kLightTreeMinLights lights) and with the choice that weighs
// every light's fluence at every vertex (the scene's tree removed, as scenes of fewer lights are
// rendered), and compared with a converged reference. Reports per choice the time, the MSE
// against the reference and the efficiency 1/(MSE · time); their ratio is the ratio of the MSEs
// at equal time. Both choices are unbiased, so the reference is the tree's at another seed.
//
// Usage: light_choice [--spp N] [--ref-spp N] [--reps N] [--threads N] [N ...]
// Defaults: 16 spp, reference 1024 spp, 3 repetitions (median time), one thread, N = 16, 64,
// 256, 1024, 4096.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bench_args.h"
#include "nimbus/render/light_tree.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace {

using namespace nimbus;

// N sphere lights on a k × k grid over [-4, 4]², radius a fifth of the spacing, each as bright
// as the others seen from afar (radiance 1/r²).
std::string lights_scene(int n, int spp, int seed) {
  const int k = int(std::ceil(std::sqrt(double(n))));
  const double step = 8.0 / k, r = 0.2 * step;
  std::string lights;
  for (int i = 0; i < n; ++i) {
    const double x = -4 + step * (i % k + 0.5), z = -4 + step * (i / k + 0.5);
    lights += (i ? ", " : "") + std::string(R"({"type": "sphere", "center": [)") +
              std::to_string(x) + ", " + std::to_string(0.5 + r) + ", " + std::to_string(z) +
              "], \"radius\": " + std::to_string(r) +
              ", \"radiance\": " + std::to_string(1 / (r * r)) + "}";
  }
  return R"({"film": {"width": 64, "height": 64},
    "camera": {"from": [0, 7, 9], "to": [0, 0, 0], "fov": 50},
    "integrator": {"spp": )" +
         std::to_string(spp) + R"(, "max_depth": 4, "seed": )" + std::to_string(seed) +
         R"(}, "lights": [)" + lights + R"(],
    "shapes": {"floor": {"type": "box", "min": [-6, -1, -6], "max": [6, 0, 6]}},
    "objects": [{"shape": "floor", "surface": {"type": "diffuse", "albedo": 0.5}}]})";
}

Scene compiled(int n, int spp, int seed, bool tree) {
  Scene scene = compile_scene(load_scene_text(lights_scene(n, spp, seed), "lights.json"));
  if (!tree) scene.light_tree = LightTree{};
  return scene;
}

double mse(const Film& film, const Film& ref) {
  double se = 0;
  const int pixels = film.width * film.height;
  for (int p = 0; p < pixels; ++p)
    for (int c = 0; c < 3; ++c) {
      const double d = film.mean(p)[c] - ref.mean(p)[c];
      se += d * d;
    }
  return se / (3.0 * pixels);
}

void bench(int n, int spp, int ref_spp, int reps, int threads) {
  RenderOptions options;
  options.threads = threads;
  const RenderResult ref = render(compiled(n, ref_spp, 977, true), options);
  double noise = 0;  // the reference's own variance, in every MSE below
  const int pixels = ref.film.width * ref.film.height;
  for (int p = 0; p < pixels; ++p) {
    const Rgb v = ref.film.variance_of_mean(p);
    noise += (v[0] + v[1] + v[2]) / (3.0 * pixels);
  }
  // Interleaved repetitions, each choice's time its median; the images do not change.
  const char* names[2] = {"light tree", "per-light choice"};
  std::vector<double> seconds[2];
  double error[2] = {0, 0};
  for (int rep = 0; rep < reps; ++rep)
    for (int c = 0; c < 2; ++c) {
      const RenderResult r = render(compiled(n, spp, 1, c == 0), options);
      seconds[c].push_back(r.seconds);
      error[c] = mse(r.film, ref.film);
    }
  double efficiency[2];
  for (int c = 0; c < 2; ++c) {
    std::vector<double>& t = seconds[c];
    std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
    efficiency[c] = 1 / (error[c] * t[t.size() / 2]);
  }
  for (int c = 0; c < 2; ++c)
    std::printf("| %d | %s | %.3f | %.3e | %.2f |\n", n, names[c],
                seconds[c][seconds[c].size() / 2], error[c], efficiency[c] / efficiency[1]);
  std::fprintf(stderr, "%d lights: reference %d spp, noise %.3e\n", n, ref_spp, noise);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  int spp = 16, ref_spp = 1024, reps = 3, threads = 1;
  std::vector<int> counts;
  bench_args::parse_args(
      argc, argv,
      {bench_args::int_flag("--spp", spp), bench_args::int_flag("--ref-spp", ref_spp),
       bench_args::int_flag("--reps", reps, 1), bench_args::int_flag("--threads", threads, 1)},
      [&](const char* a) { counts.push_back(std::stoi(a)); });
  if (counts.empty()) counts = {16, 64, 256, 1024, 4096};
  std::printf(
      "| lights | choice | time (s) | MSE | efficiency vs per-light |\n|---|---|---|---|---|\n");
  for (const int n : counts) bench(n, spp, ref_spp, reps, threads);
}
