// The nimbus command line: `nimbus render SCENE ...`.

#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "nimbus/io/atomic_file.h"
#include "nimbus/io/output.h"
#include "nimbus/render/renderer.h"
#include "nimbus/render/stats.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace {

constexpr int kExitFailure = 1;
constexpr int kExitBadInput = 2;

struct RenderArgs {
  std::string scene;
  std::vector<std::string> outputs;
  std::vector<std::string> sets;
  int spp = 0;
  long long seed = -1;
  int threads = 0;
  std::string stats;
  bool quiet = false;
};

void print_progress(double fraction, double elapsed) {
  const int width = 40, filled = static_cast<int>(fraction * width);
  const double eta = fraction > 0 ? elapsed * (1 - fraction) / fraction : 0;
  std::fprintf(stderr, "\r[%s%s] %5.1f%%  %6.1fs elapsed  ETA %6.1fs",
               std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(),
               100 * fraction, elapsed, eta);
  std::fflush(stderr);
}

int run_render(const RenderArgs& args) {
  using namespace nimbus;
  std::vector<std::string> overrides = args.sets;
  if (args.spp > 0) overrides.push_back(fmt::format("integrator.spp={}", args.spp));
  if (args.seed >= 0) overrides.push_back(fmt::format("integrator.seed={}", args.seed));

  std::vector<std::string> outputs = args.outputs;
  if (outputs.empty()) {
    const std::string stem = std::filesystem::path(args.scene).stem().string();
    outputs = {stem + ".exr", stem + ".png"};
  }
  try {
    for (const std::string& out : outputs) check_output_path(out);
    if (!args.stats.empty()) check_writable_path(args.stats);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitBadInput;
  }

  Scene scene;
  try {
    scene = compile_scene(load_scene_file(args.scene, overrides));
  } catch (const SceneError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitBadInput;
  }

  RenderOptions options;
  options.threads = args.threads;
  const bool show_progress = !args.quiet && isatty(fileno(stderr));
  const auto start = std::chrono::steady_clock::now();
  if (show_progress)
    options.progress = [&](double f) {
      print_progress(
          f, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    };
  const RenderResult result = render(scene, options);
  if (show_progress) std::fprintf(stderr, "\n");

  // All or nothing: if one output cannot be written, remove those already written.
  std::vector<std::string> written;
  try {
    const Image image = to_image(result.film);
    for (const std::string& out : outputs) {
      write_image(out, image);
      written.push_back(out);
    }
    if (!args.stats.empty()) {
      const std::string text = render_stats(scene, result, args.scene).dump(2) + "\n";
      write_atomically(args.stats, [&](const std::string& tmp) {
        std::ofstream f(tmp);
        f << text;
        if (!f) throw std::runtime_error("cannot write");
      });
    }
  } catch (const std::exception& e) {
    for (const std::string& w : written) std::filesystem::remove(w);
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitFailure;
  }
  if (!args.quiet) {
    const double samples =
        double(scene.settings.width) * scene.settings.height * scene.settings.spp;
    std::string list;
    for (const auto& o : outputs) list += (list.empty() ? "" : ", ") + o;
    std::fprintf(stderr, "nimbus: %dx%d, %d spp in %.2f s (%.3g samples/s, %d threads) -> %s\n",
                 scene.settings.width, scene.settings.height, scene.settings.spp, result.seconds,
                 samples / result.seconds, result.threads, list.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"nimbus: renders functionally specified objects and participating media"};
  app.set_version_flag("--version", std::string("nimbus ") + NIMBUS_VERSION);
  app.require_subcommand(1);

  RenderArgs args;
  CLI::App* render = app.add_subcommand("render", "Render a scene file to EXR and/or PNG");
  render->add_option("scene", args.scene, "Scene file (JSON)")->required();
  render->add_option("-o,--output", args.outputs,
                     "Output image; repeatable; .exr (linear float) or .png (8-bit sRGB). "
                     "Default: <scene stem>.exr and .png in the current directory");
  render->add_option("--spp", args.spp, "Samples per pixel (overrides integrator.spp)")
      ->check(CLI::PositiveNumber);
  render->add_option("--seed", args.seed, "Random seed (overrides integrator.seed)")
      ->check(CLI::NonNegativeNumber);
  render->add_option("--threads", args.threads, "Worker threads (default: all cores)")
      ->check(CLI::PositiveNumber);
  render->add_option("--set", args.sets,
                     "Override a scene key: --set integrator.spp=16 (dotted path, JSON value); "
                     "repeatable");
  render->add_option("--stats", args.stats, "Write render statistics as JSON to this file");
  render->add_flag("-q,--quiet", args.quiet, "Print nothing but errors");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitBadInput;
  }
  try {
    return run_render(args);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitFailure;
  }
}
