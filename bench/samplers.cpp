// The samplers (integrator.sampler, issue 13): efficiency of zsobol against independent at equal
// samples, and the sampler's own cost per number.
//
// Per scene: a reference rendered with the independent sampler at --ref-spp, then, interleaved
// over --reps repetitions (each with its own seed), both samplers at --spp on one thread. Reports
// per sampler the mean over repetitions of the MSE against the reference (over pixels and
// channels, minus the reference's own expected error, the mean of its pixels' variances of the
// mean, which independent samples estimate), the median time per sample, and the efficiency
// 1 / (MSE · time) of zsobol relative to independent. Then the cost of the numbers alone: a
// PathSampler per pixel sample drawing the camera's, the wavelength's and 8 bounces' dimensions.
// Output: Markdown.
//
// Usage: samplers [--spp N] [--ref-spp N] [--reps N] [--width N] [--set KEY=VALUE]...
//                 [scene.json ...]
// Defaults: 16 spp, reference 1024 spp, 5 repetitions, width 48, scenes/cloud.json.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "bench_args.h"
#include "nimbus/render/path_sampler.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace {

using namespace nimbus;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

Scene sized_scene(const std::string& path, std::vector<std::string> overrides, int width, int spp,
                  uint64_t seed, const std::string& sampler) {
  overrides.push_back("integrator.spp=" + std::to_string(spp));
  overrides.push_back("integrator.seed=" + std::to_string(seed));
  overrides.push_back("integrator.sampler=\"" + sampler + "\"");
  SceneDesc desc = load_scene_file(path, overrides);
  desc.settings.height = std::max(1, desc.settings.height * width / desc.settings.width);
  desc.settings.width = width;
  return compile_scene(desc);
}

// Nanoseconds per pixel sample for the numbers of a path with `bounces` bounces and 1 light.
double sampler_ns_per_sample(RenderSettings::Sampler kind, int bounces) {
  RenderSettings settings;
  settings.width = settings.height = 256;
  settings.spp = 16;
  settings.sampler = kind;
  const ZSobol zsobol(settings.width, settings.height, settings.seed);
  double sink = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      for (int s = 0; s < settings.spp; ++s) {
        PathSampler sampler(settings, zsobol, x, y, uint64_t(y * 256 + x), uint64_t(s));
        sink += sampler.get2d(SampleDims::kCamera)[0] + sampler.get1d(SampleDims::kWavelength);
        for (int d = 0; d < bounces; ++d) {
          const uint32_t b = SampleDims::bounce(d, 1);
          sampler.first_from(b + SampleDims::kFreeFlight);
          sink += sampler.rng().uniform();
          sampler.done();
          sink += sampler.get2d(SampleDims::light(b, 0))[1] +
                  sampler.get2d(b + SampleDims::kDirection)[0] +
                  sampler.get1d(b + SampleDims::kChoice) + sampler.get1d(b + SampleDims::kRoulette);
        }
      }
  const double ns =
      std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
  if (sink < 0) std::printf("%g", sink);  // keeps the loop
  return ns / (64.0 * 64.0 * settings.spp);
}

}  // namespace

int main(int argc, char** argv) {
  int spp = 16, ref_spp = 1024, reps = 5, width = 48;
  std::vector<std::string> scenes, overrides;
  bench_args::parse_args(
      argc, argv,
      {bench_args::int_flag("--spp", spp), bench_args::int_flag("--ref-spp", ref_spp),
       bench_args::int_flag("--reps", reps), bench_args::int_flag("--width", width),
       bench_args::list_flag("--set", overrides)},
      [&](const char* a) { scenes.push_back(a); });
  if (scenes.empty()) scenes.push_back(std::string(NIMBUS_SOURCE_DIR) + "/scenes/cloud.json");
  RenderOptions one_thread;
  one_thread.threads = 1;

  std::printf(
      "| scene | MSE independent | MSE zsobol | ratio | s/sample independent | "
      "s/sample zsobol | efficiency zsobol / independent |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (const std::string& path : scenes) {
    const RenderResult ref = render(
        sized_scene(path, overrides, width, ref_spp, 987654321, "independent"), RenderOptions{});
    double ref_var = 0;
    const int pixels = ref.film.pixels();
    for (int p = 0; p < pixels; ++p)
      for (int c = 0; c < 3; ++c) ref_var += ref.film.variance_of_mean(p)[c] / (3.0 * pixels);
    std::vector<double> mse[2], time[2];
    const char* names[2] = {"independent", "zsobol"};
    for (int rep = 0; rep < reps; ++rep)
      for (int k = 0; k < 2; ++k) {
        const Scene scene = sized_scene(path, overrides, width, spp, uint64_t(rep + 1), names[k]);
        const RenderResult r = render(scene, one_thread);
        double se = 0;
        for (int p = 0; p < pixels; ++p) {
          const Rgb d = r.film.mean(p) - ref.film.mean(p);
          for (int c = 0; c < 3; ++c) se += d[c] * d[c] / (3.0 * pixels);
        }
        mse[k].push_back(se - ref_var);
        time[k].push_back(r.seconds / (double(pixels) * spp));
      }
    double m[2];
    for (int k = 0; k < 2; ++k) {
      m[k] = 0;
      for (double e : mse[k]) m[k] += e / reps;
    }
    const double t0 = median(time[0]), t1 = median(time[1]);
    const std::string name = path.substr(path.find_last_of('/') + 1);
    std::printf("| %s | %.4g | %.4g | %.3f | %.3g | %.3g | %.2f |\n", name.c_str(), m[0], m[1],
                m[1] / m[0], t0, t1, (m[0] * t0) / (m[1] * t1));
  }

  std::printf(
      "\nNumbers of one pixel sample (camera, wavelength, 8 bounces with 1 light), "
      "median of 5:\n\n| sampler | ns per pixel sample |\n|---|---|\n");
  for (auto kind : {RenderSettings::Sampler::Independent, RenderSettings::Sampler::ZSobol}) {
    std::vector<double> ns;
    for (int i = 0; i < 5; ++i) ns.push_back(sampler_ns_per_sample(kind, 8));
    std::printf("| %s | %.0f |\n",
                kind == RenderSettings::Sampler::ZSobol ? "zsobol" : "independent", median(ns));
  }
}
