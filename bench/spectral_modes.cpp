// Spectral mode against rgb mode (issue 8): cost per sample and colour noise at equal time.
// Renders the scene in rgb mode and in spectral mode with 4 and 8 wavelengths (tracking as the
// scene says), interleaved over repetitions on one thread, and reports per mode the median time
// per sample, the mean per-pixel variance of one sample per channel (linear sRGB, from the
// film's sums of squares, so each mode is measured against its own mean: rgb and spectral modes
// converge to slightly different colours where RGB inputs are upsampled), and the noise at equal
// time relative to rgb mode, sqrt(variance × time per sample / (rgb's)). Output: Markdown.
//
// Usage: spectral_modes [--spp N] [--reps N] [--width N] [--wavelengths N,N,...] [scene.json]
// Defaults: 8 spp, 3 repetitions, width 160 (height kept in proportion), wavelengths 4,8,
// scenes/cloud.json.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "bench_args.h"
#include "nimbus/render/renderer.h"
#include "nimbus/render/setting_names.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace {

using namespace nimbus;

struct Mode {
  const char* name;
  std::vector<std::string> overrides;
  std::vector<double> seconds_per_sample;
  Rgb variance{0.0};  // of one sample, averaged over pixels (last repetition)
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  int spp = 8, reps = 3, width = 160;
  std::vector<int> wavelengths = {4, 8};
  std::string scene_path = std::string(NIMBUS_SOURCE_DIR) + "/scenes/cloud.json";
  const auto set_wavelengths = [&](const char* v) {
    wavelengths.clear();
    std::stringstream list(v);
    for (std::string n; std::getline(list, n, ',');) wavelengths.push_back(std::stoi(n));
  };
  bench_args::parse_args(argc, argv,
                         {bench_args::int_flag("--spp", spp),
                          bench_args::int_flag("--reps", reps),
                          bench_args::int_flag("--width", width),
                          {"--wavelengths", set_wavelengths}},
                         [&](const char* a) { scene_path = a; });
  std::vector<std::string> names = {"rgb"};
  std::vector<Mode> modes = {{"", {"spectrum.mode=\"rgb\""}, {}}};
  for (int n : wavelengths) {
    names.push_back("spectral, N = " + std::to_string(n));
    modes.push_back(
        {"", {"spectrum.mode=\"spectral\"", "spectrum.wavelengths=" + std::to_string(n)}, {}});
  }
  for (size_t i = 0; i < modes.size(); ++i) modes[i].name = names[i].c_str();
  std::string tracking;
  for (int rep = 0; rep < reps; ++rep)
    for (Mode& mode : modes) {
      std::vector<std::string> overrides = mode.overrides;
      overrides.push_back("integrator.spp=" + std::to_string(spp));
      const SceneDesc desc = load_scene_file(scene_path, overrides);
      SceneDesc sized = desc;
      sized.settings.height = std::max(1, desc.settings.height * width / desc.settings.width);
      sized.settings.width = width;
      tracking = name_of(kTrackingModeNames, desc.settings.tracking.mode);
      const Scene scene = compile_scene(sized);
      const RenderResult r = render(scene, RenderOptions{1, {}, {}, {}});
      const double samples = double(scene.settings.width) * scene.settings.height * spp;
      mode.seconds_per_sample.push_back(r.seconds / samples);
      Rgb var(0.0);
      const int pixels = scene.settings.width * scene.settings.height;
      for (int p = 0; p < pixels; ++p) var += r.film.variance_of_mean(p) * double(spp);
      mode.variance = var / double(pixels);
    }
  std::printf("%s, %d spp, width %d, tracking %s, %d repetitions (medians), 1 thread\n\n",
              scene_path.c_str(), spp, width, tracking.c_str(), reps);
  std::printf(
      "| mode | µs / sample | × rgb | variance / sample (R, G, B) | noise at equal time (R, G, B) "
      "× rgb |\n");
  std::printf("|---|---|---|---|---|\n");
  const double t_rgb = median(modes[0].seconds_per_sample);
  for (const Mode& m : modes) {
    const double t = median(m.seconds_per_sample);
    double rel[3];
    for (int c = 0; c < 3; ++c)
      rel[c] = std::sqrt(m.variance[c] * t / (modes[0].variance[c] * t_rgb));
    std::printf("| %s | %.1f | %.2f | %.4g, %.4g, %.4g | %.2f, %.2f, %.2f |\n", m.name, t * 1e6,
                t / t_rgb, m.variance[0], m.variance[1], m.variance[2], rel[0], rel[1], rel[2]);
  }
  return 0;
}
