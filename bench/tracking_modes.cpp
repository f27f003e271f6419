// Tracking modes at equal sample count (issue 5): renders each benchmark scene with every mode
// and compares it with a converged reference, rendered once and cached. Reports per mode the
// time, the MSE against the reference, the efficiency 1/(MSE · time) relative to delta tracking,
// and the work counters. Output: a Markdown table per scene.
//
// The reference is delta tracking (Woodcock, the classic baseline, with shadow rays on its own
// channel) at another seed: it shares no tracker with the spectral modes, so it cannot favour
// the paper's method, and its own noise (the mean variance of its pixels, printed) is what every
// mode's MSE carries on top of its own error.
//
// Usage: tracking_modes [--spp N] [--ref-spp N] [--reps N] [--cache DIR] [scene.json ...]
// Defaults: 16 spp, reference 512 spp, 3 repetitions (median time), cache build/bench-cache, the
// scenes of scenes/bench/.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bench_args.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace {

using namespace nimbus;

struct Mode {
  const char* name;
  std::vector<std::string> overrides;
};

// Shadow rays are ratio-tracked unless the name says residual ratio tracking or ray marching, so
// that the tables in docs/benchmarks/tracking-modes.md, made before residual ratio tracking became
// the default, compare.
const std::vector<Mode> kModes = {
    {"delta",
     {"integrator.tracking=\"delta\"", "integrator.absorption=\"collide\"",
      "integrator.transmittance=\"ratio\""}},
    {"delta, residual ratio tracking",
     {"integrator.tracking=\"delta\"", "integrator.absorption=\"collide\"",
      "integrator.transmittance=\"residual-ratio\""}},
    {"spectral-max",
     {"integrator.tracking=\"spectral-max\"", "integrator.absorption=\"weight\"",
      "integrator.transmittance=\"ratio\""}},
    {"delta, unbiased ray marching",
     {"integrator.tracking=\"delta\"", "integrator.absorption=\"collide\"",
      "integrator.transmittance=\"ray-marching\""}},
    {"spectral-history (collide)",
     {"integrator.tracking=\"spectral-history\"", "integrator.absorption=\"collide\"",
      "integrator.transmittance=\"ratio\""}},
    {"spectral-history",
     {"integrator.tracking=\"spectral-history\"", "integrator.absorption=\"weight\"",
      "integrator.transmittance=\"ratio\""}},
    {"spectral-history, residual ratio tracking",
     {"integrator.tracking=\"spectral-history\"", "integrator.absorption=\"weight\"",
      "integrator.transmittance=\"residual-ratio\""}},
    {"spectral-history, unbiased ray marching",
     {"integrator.tracking=\"spectral-history\"", "integrator.absorption=\"weight\"",
      "integrator.transmittance=\"ray-marching\""}},
    {"spectral-history + decomposition",
     {"integrator.tracking=\"spectral-history\"", "integrator.absorption=\"weight\"",
      "integrator.decomposition=true", "integrator.transmittance=\"residual-ratio\""}},
    {"spectral-mis", {"integrator.tracking=\"spectral-mis\"", "integrator.absorption=\"collide\""}},
    {"spectral-mis, every light per vertex",
     {"integrator.tracking=\"spectral-mis\"", "integrator.absorption=\"collide\"",
      "integrator.light_sampling=\"all\""}},
};

// The reference image: pixel means and the mean variance of those means over pixels and
// channels. Cached as raw doubles: the means, then the variance.
struct Reference {
  std::vector<Rgb> mean;
  double noise = 0;
};

Reference reference(const std::string& scene_path, int spp, const std::string& cache) {
  const std::string name = std::filesystem::path(scene_path).stem().string();
  const std::string file = cache + "/" + name + "-delta-" + std::to_string(spp) + ".bin";
  Scene scene = compile_scene(load_scene_file(
      scene_path, {"integrator.tracking=\"delta\"", "integrator.absorption=\"collide\"",
                   "integrator.decomposition=false", "integrator.seed=977",
                   "integrator.spp=" + std::to_string(spp)}));
  const size_t n = size_t(scene.settings.width) * scene.settings.height;
  Reference ref{std::vector<Rgb>(n), 0};
  if (std::ifstream in{file, std::ios::binary}) {
    in.read(reinterpret_cast<char*>(ref.mean.data()), std::streamsize(n * sizeof(Rgb)));
    in.read(reinterpret_cast<char*>(&ref.noise), sizeof(double));
    if (in) return ref;
  }
  std::fprintf(stderr, "rendering the reference of %s at %d spp...\n", name.c_str(), spp);
  const RenderResult r = render(scene);
  for (size_t p = 0; p < n; ++p) {
    ref.mean[p] = r.film.mean(int(p));
    const Rgb v = r.film.variance_of_mean(int(p));
    ref.noise += (v[0] + v[1] + v[2]) / (3.0 * double(n));
  }
  std::filesystem::create_directories(cache);
  std::ofstream out{file, std::ios::binary};
  out.write(reinterpret_cast<const char*>(ref.mean.data()), std::streamsize(n * sizeof(Rgb)));
  out.write(reinterpret_cast<const char*>(&ref.noise), sizeof(double));
  std::fprintf(stderr, "reference: %.1f s\n", r.seconds);
  return ref;
}

void bench_scene(const std::string& path, int spp, int ref_spp, int reps,
                 const std::string& cache) {
  const Reference ref = reference(path, ref_spp, cache);
  std::printf(
      "\n### %s (%d spp, median time of %d; reference: delta tracking, %d spp, noise %.3e)\n\n",
      path.c_str(), spp, reps, ref_spp, ref.noise);
  std::printf(
      "| mode | time (s) | MSE | efficiency vs delta | path segments | density lookups | real "
      "collisions | null collisions | clamped |\n|---|---|---|---|---|---|---|---|---|\n");
  // Every repetition renders every mode, interleaved, so that a slow spell of the shared machine
  // touches all modes alike; each mode's time is its median. The images do not change between
  // repetitions (same seed and samples).
  std::vector<RenderResult> results;
  std::vector<std::vector<double>> seconds(kModes.size());
  for (int rep = 0; rep < reps; ++rep)
    for (size_t m = 0; m < kModes.size(); ++m) {
      std::vector<std::string> overrides = kModes[m].overrides;
      overrides.push_back("integrator.spp=" + std::to_string(spp));
      RenderResult r = render(compile_scene(load_scene_file(path, overrides)));
      seconds[m].push_back(r.seconds);
      if (rep == 0) results.push_back(std::move(r));
    }
  double delta_efficiency = 0;
  for (size_t m = 0; m < kModes.size(); ++m) {
    const RenderResult& r = results[m];
    std::vector<double>& t = seconds[m];
    std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
    const double time = t[t.size() / 2];
    double se = 0;
    for (size_t p = 0; p < ref.mean.size(); ++p)
      for (int c = 0; c < 3; ++c) {
        const double d = r.film.mean(int(p))[c] - ref.mean[p][c];
        se += d * d;
      }
    const double mse = se / (3.0 * double(ref.mean.size()));
    const double efficiency = 1 / (mse * time);
    if (delta_efficiency == 0) delta_efficiency = efficiency;
    const Counters& k = r.counters;
    std::printf("| %s | %.3f | %.3e | %.2f | %.3e | %.3e | %.3e | %.3e | %llu |\n", kModes[m].name,
                time, mse, efficiency / delta_efficiency, double(k.tracking.tentative_collisions),
                double(k.tracking.lookups), double(k.real_collisions), double(k.null_collisions()),
                static_cast<unsigned long long>(k.tracking.clamped));
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  int spp = 16, ref_spp = 512, reps = 3;
  std::string cache = "build/bench-cache";
  std::vector<std::string> scenes;
  bench_args::parse_args(
      argc, argv,
      {bench_args::int_flag("--spp", spp), bench_args::int_flag("--ref-spp", ref_spp),
       bench_args::int_flag("--reps", reps, 1), bench_args::string_flag("--cache", cache)},
      [&](const char* a) { scenes.push_back(a); });
  if (scenes.empty())
    for (const char* s : {"chromatic_cloud", "marble", "skin", "haze"})
      scenes.push_back(std::string("scenes/bench/") + s + ".json");
  for (const std::string& s : scenes) bench_scene(s, spp, ref_spp, reps, cache);
}
