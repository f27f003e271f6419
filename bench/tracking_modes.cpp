// Tracking modes at equal sample count (issue 5): renders each benchmark scene with every mode
// and compares it with a converged reference, rendered once and cached. Reports per mode the
// time, the MSE against the reference, the efficiency 1/(MSE · time) relative to delta tracking,
// and the work counters. Output: a Markdown table per scene.
//
// Usage: tracking_modes [--spp N] [--ref-spp N] [--cache DIR] [scene.json ...]
// Defaults: 16 spp, reference 512 spp (spectral-history, weights, decomposition, another seed),
// cache build/bench-cache, the scenes of scenes/bench/.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace {

using namespace nimbus;

struct Mode {
  const char* name;
  std::vector<std::string> overrides;
};

const std::vector<Mode> kModes = {
    {"delta", {"integrator.tracking=\"delta\"", "integrator.absorption=\"collide\""}},
    {"spectral-max", {"integrator.tracking=\"spectral-max\"", "integrator.absorption=\"weight\""}},
    {"spectral-history (collide)",
     {"integrator.tracking=\"spectral-history\"", "integrator.absorption=\"collide\""}},
    {"spectral-history",
     {"integrator.tracking=\"spectral-history\"", "integrator.absorption=\"weight\""}},
    {"spectral-history + decomposition",
     {"integrator.tracking=\"spectral-history\"", "integrator.absorption=\"weight\"",
      "integrator.decomposition=true", "integrator.transmittance=\"residual-ratio\""}},
    {"spectral-mis", {"integrator.tracking=\"spectral-mis\"", "integrator.absorption=\"collide\""}},
};

// The reference image's pixel means, cached as raw doubles after (width, height, spp).
std::vector<Rgb> reference(const std::string& scene_path, int spp, const std::string& cache) {
  const std::string name = std::filesystem::path(scene_path).stem().string();
  const std::string file = cache + "/" + name + "-" + std::to_string(spp) + ".bin";
  Scene scene = compile_scene(load_scene_file(
      scene_path, {"integrator.tracking=\"spectral-history\"", "integrator.absorption=\"weight\"",
                   "integrator.decomposition=true", "integrator.seed=977",
                   "integrator.spp=" + std::to_string(spp)}));
  const size_t n = size_t(scene.settings.width) * scene.settings.height;
  std::vector<Rgb> ref(n);
  if (std::ifstream in{file, std::ios::binary}) {
    in.read(reinterpret_cast<char*>(ref.data()), std::streamsize(n * sizeof(Rgb)));
    if (in) return ref;
  }
  std::fprintf(stderr, "rendering the reference of %s at %d spp...\n", name.c_str(), spp);
  const RenderResult r = render(scene);
  for (size_t p = 0; p < n; ++p) ref[p] = r.film.mean(int(p));
  std::filesystem::create_directories(cache);
  std::ofstream out{file, std::ios::binary};
  out.write(reinterpret_cast<const char*>(ref.data()), std::streamsize(n * sizeof(Rgb)));
  std::fprintf(stderr, "reference: %.1f s\n", r.seconds);
  return ref;
}

void bench_scene(const std::string& path, int spp, int ref_spp, const std::string& cache) {
  const std::vector<Rgb> ref = reference(path, ref_spp, cache);
  std::printf("\n### %s (%d spp; reference %d spp)\n\n", path.c_str(), spp, ref_spp);
  std::printf(
      "| mode | time (s) | MSE | efficiency vs delta | path segments | density lookups | real "
      "collisions | null collisions | clamped |\n|---|---|---|---|---|---|---|---|---|\n");
  double delta_efficiency = 0;
  for (const Mode& mode : kModes) {
    std::vector<std::string> overrides = mode.overrides;
    overrides.push_back("integrator.spp=" + std::to_string(spp));
    const Scene scene = compile_scene(load_scene_file(path, overrides));
    const RenderResult r = render(scene);
    double se = 0;
    for (size_t p = 0; p < ref.size(); ++p)
      for (int c = 0; c < 3; ++c) {
        const double d = r.film.mean(int(p))[c] - ref[p][c];
        se += d * d;
      }
    const double mse = se / (3.0 * double(ref.size()));
    const double efficiency = 1 / (mse * r.seconds);
    if (delta_efficiency == 0) delta_efficiency = efficiency;
    const Counters& k = r.counters;
    std::printf("| %s | %.2f | %.3e | %.2f | %.3e | %.3e | %.3e | %.3e | %llu |\n", mode.name,
                r.seconds, mse, efficiency / delta_efficiency,
                double(k.tracking.tentative_collisions), double(k.tracking.lookups),
                double(k.real_collisions), double(k.null_collisions()),
                static_cast<unsigned long long>(k.tracking.clamped));
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  int spp = 16, ref_spp = 512;
  std::string cache = "build/bench-cache";
  std::vector<std::string> scenes;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--spp" && i + 1 < argc)
      spp = std::stoi(argv[++i]);
    else if (a == "--ref-spp" && i + 1 < argc)
      ref_spp = std::stoi(argv[++i]);
    else if (a == "--cache" && i + 1 < argc)
      cache = argv[++i];
    else
      scenes.push_back(a);
  }
  if (scenes.empty())
    for (const char* s : {"chromatic_cloud", "marble", "skin", "haze"})
      scenes.push_back(std::string("scenes/bench/") + s + ".json");
  for (const std::string& s : scenes) bench_scene(s, spp, ref_spp, cache);
}
