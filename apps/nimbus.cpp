// The nimbus command line: `nimbus render SCENE ...`, `nimbus experiment NAME --out DIR` and
// `nimbus export-vdb SCENE -o OUT.vdb --voxel-size H`.

#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "nimbus/experiments/experiment.h"
#include "nimbus/io/atomic_file.h"
#include "nimbus/io/film_image.h"
#include "nimbus/io/output.h"
#include "nimbus/io/vdb_export.h"
#include "nimbus/render/memory_estimate.h"
#include "nimbus/render/path_spectra.h"
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
  std::string max_memory;  // empty: the system's available memory
  bool quiet = false;
};

// SIGINT, SIGTERM and SIGHUP: the first one during a render stops it before its next pixel
// (nothing is written, exit 128 + the signal's number); during writing, or a second one, removes
// every temporary file and ends the process by the signal at once.
std::atomic<int> g_signal{0};
std::atomic<bool> g_writing{false};

extern "C" void on_stop_signal(int sig) {
  if (g_signal.exchange(sig) != 0 || g_writing.load()) {
    nimbus::remove_temporary_files_now();
    std::signal(sig, SIG_DFL);
    std::raise(sig);
  }
}

void catch_stop_signals() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, on_stop_signal);
}

const char* signal_name(int sig) {
  return sig == SIGINT    ? "SIGINT"
         : sig == SIGTERM ? "SIGTERM"
         : sig == SIGHUP  ? "SIGHUP"
                          : "a signal";
}

// One line, redrawn: what is being done, a bar, the fraction, the time so far and the ETA.
void print_progress(const char* what, double fraction, double elapsed) {
  const int width = 40, filled = static_cast<int>(fraction * width);
  const double eta = fraction > 0 ? elapsed * (1 - fraction) / fraction : 0;
  std::fprintf(stderr, "\r%-8s [%s%s] %5.1f%%  %6.1fs elapsed  ETA %6.1fs", what,
               std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(),
               100 * fraction, elapsed, eta);
  std::fflush(stderr);
}

// A progress callback that draws `what`'s bar, timed from when it is made.
std::function<void(double)> progress_bar(const char* what) {
  const auto start = std::chrono::steady_clock::now();
  return [what, start](double f) {
    print_progress(what, f,
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  };
}

// Refuses, with one line and exit 2, a render that the machine (or --max-memory) cannot hold,
// before anything large is allocated (render/memory_estimate.h); 0 if it fits.
int check_memory(const nimbus::SceneDesc& desc, const RenderArgs& args) {
  using namespace nimbus;
  int octrees = 1;
  for (const ObjectDesc& o : desc.objects)
    octrees += o.medium >= 0 && o.surface.type == SurfaceDesc::Type::Dielectric;
  const int bins = desc.spectrum.mode == SpectralSettings::Mode::Spectral ? kSpectralBins : 3;
  const int threads = args.threads > 0 ? args.threads : int(std::thread::hardware_concurrency());
  const MemoryEstimate need =
      estimate_render_memory(desc.film.width, desc.film.height, octrees, bins, threads);
  std::uint64_t limit = 0;
  std::string source = "available";
  try {
    if (!args.max_memory.empty()) {
      limit = parse_memory_size(args.max_memory);
      source = "allowed by --max-memory";
    } else {
      limit = available_memory();
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "nimbus: --max-memory: %s\n", e.what());
    return kExitBadInput;
  }
  if (limit > 0 && need.total() > double(limit)) {
    std::fprintf(stderr,
                 "nimbus: the render needs about %s (film %s, image %s, majorant octrees %s), "
                 "more than the %s %s\n",
                 format_memory(need.total()).c_str(), format_memory(need.film).c_str(),
                 format_memory(need.image).c_str(), format_memory(need.octrees).c_str(),
                 format_memory(double(limit)).c_str(), source.c_str());
    return kExitBadInput;
  }
  return 0;
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

  SceneDesc desc;
  try {
    desc = load_scene_file(args.scene, overrides);
  } catch (const SceneError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitBadInput;
  }

  if (const int refused = check_memory(desc, args); refused != 0) return refused;

  const bool show_progress = !args.quiet && isatty(fileno(stderr));
  // The majorant octrees can take seconds to build (deep trees, sampled bounds): they get a
  // bar of their own, and a signal stops them too.
  BuildMonitor monitor;
  monitor.cancel = [] { return g_signal.load() != 0; };
  if (show_progress) monitor.progress = progress_bar("octrees");
  Scene scene;
  try {
    scene = compile_scene(desc, monitor);
  } catch (const SceneError& e) {
    if (show_progress) std::fprintf(stderr, "\n");
    std::fprintf(stderr, "%s\n", e.what());
    return kExitBadInput;
  }
  if (show_progress) std::fprintf(stderr, "\n");
  if (const int sig = g_signal.load(); sig != 0) {
    std::fprintf(stderr,
                 "nimbus: stopped by %s while building the majorant octrees; nothing written\n",
                 signal_name(sig));
    return 128 + sig;
  }

  RenderOptions options;
  options.threads = args.threads;
  options.cancel = [] { return g_signal.load() != 0; };
  if (show_progress) options.progress = progress_bar("render");
  const RenderResult result = render(scene, options);
  if (show_progress) std::fprintf(stderr, "\n");
  if (const int sig = g_signal.load(); sig != 0) {
    std::fprintf(stderr, "nimbus: stopped by %s before the render finished; nothing written\n",
                 signal_name(sig));
    return 128 + sig;
  }
  if (const uint64_t n = result.counters.rejected_samples; n > 0)
    std::fprintf(stderr,
                 "nimbus: warning: %llu samples were NaN or infinite and counted as 0 "
                 "(counters.rejected_samples in --stats)\n",
                 static_cast<unsigned long long>(n));

  // All or nothing: every output is written to its temporary file first, and only when all are
  // complete are they renamed into place (io/atomic_file.h).
  g_writing = true;
  try {
    OutputTransaction outputs_of_this_run;
    const Image image = to_image(result.film);
    for (const std::string& out : outputs) write_image(out, image);
    if (!args.stats.empty()) {
      const std::string text = render_stats(scene, result, args.scene).dump(2) + "\n";
      write_atomically(args.stats, [&](const std::string& tmp) {
        std::ofstream f(tmp);
        f << text;
        if (!f) throw std::runtime_error("cannot write");
      });
    }
    outputs_of_this_run.commit();
  } catch (const std::exception& e) {
    g_writing = false;
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitFailure;
  }
  g_writing = false;
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

// nimbus's data (scenes/, tools/plot_*.py): share/nimbus beside the executable (the build tree
// links it there) or above it (an installed prefix: bin/nimbus, share/nimbus).
std::filesystem::path data_dir() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return "share/nimbus";
  for (const std::filesystem::path& d : {exe.parent_path() / "share" / "nimbus",
                                         exe.parent_path().parent_path() / "share" / "nimbus"})
    if (std::filesystem::exists(d / "scenes")) return d;
  return exe.parent_path().parent_path() / "share" / "nimbus";
}

struct ExperimentArgs {
  std::string name;
  std::string out;
  std::string scenes = (data_dir() / "scenes").string();
  bool quick = false;
  bool no_plot = false;
  long long seed = 0;
  int threads = 0;
};

// The interpreter the plotting scripts name in their first line.
constexpr const char* kPlotPython = "/usr/bin/python3";

// Runs tools/plot_<name>.py on the experiment's directory, if there is such a script and
// matplotlib can be imported; otherwise says why there is no plot. Never fails the experiment.
void plot(const std::string& name, const std::filesystem::path& out) {
  std::string stem = name;
  std::replace(stem.begin(), stem.end(), '-', '_');
  const std::filesystem::path script = data_dir() / "tools" / ("plot_" + stem + ".py");
  if (!std::filesystem::exists(script)) return;
  const std::string probe = fmt::format("{} -c 'import matplotlib' >/dev/null 2>&1", kPlotPython);
  if (std::system(probe.c_str()) != 0) {
    std::fprintf(stderr,
                 "nimbus: note: no plot: %s with matplotlib is not available; the CSV files are "
                 "in %s (plot later with %s %s %s)\n",
                 kPlotPython, out.c_str(), kPlotPython, script.c_str(), out.c_str());
    return;
  }
  const std::string command =
      fmt::format("{} '{}' '{}'", kPlotPython, script.string(), out.string());
  if (std::system(command.c_str()) != 0)
    std::fprintf(stderr, "nimbus: note: %s failed; the CSV files are in %s\n", script.c_str(),
                 out.c_str());
}

int run_experiment(const ExperimentArgs& args) {
  using namespace nimbus;
  const auto& all = experiments();
  const auto it = std::find_if(all.begin(), all.end(),
                               [&](const Experiment& e) { return e.name == args.name; });
  if (it == all.end()) {
    std::string names;
    for (const Experiment& e : all) names += (names.empty() ? "" : ", ") + e.name;
    std::fprintf(stderr, "nimbus: unknown experiment \"%s\" (one of: %s)\n", args.name.c_str(),
                 names.c_str());
    return kExitBadInput;
  }
  ExperimentOptions options;
  options.out = args.out;
  options.scenes = args.scenes;
  options.quick = args.quick;
  options.seed = uint64_t(args.seed);
  options.threads = args.threads;
  try {
    std::filesystem::create_directories(options.out);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nimbus: %s: cannot create the directory (%s)\n", args.out.c_str(),
                 e.what());
    return kExitBadInput;
  }
  const auto start = std::chrono::steady_clock::now();
  ExperimentReport report;
  try {
    report = it->run(options);
  } catch (const SceneError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitBadInput;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s (%s) in %.1f s\n%s", it->name.c_str(), args.quick ? "quick" : "full", seconds,
              report.summary.c_str());
  for (const auto& f : report.files) std::printf("  wrote %s\n", f.c_str());
  if (!args.no_plot) plot(it->name, options.out);
  return 0;
}

struct ExportArgs {
  std::string scene;
  std::string output;
  double voxel_size = 0;
  int object = -1;  // -1: the first object that holds a medium
  std::vector<std::string> sets;
  bool quiet = false;
};

// `nimbus export-vdb`: one object's medium as an OpenVDB fog volume (io/vdb_export.h). Bad input
// (the scene, the object, the voxel size, the output path) is exit 2 with one line and nothing
// written; a signal stops the build as it stops a render.
int run_export_vdb(const ExportArgs& args) {
  using namespace nimbus;
  try {
    check_writable_path(args.output);
    std::string ext = std::filesystem::path(args.output).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (ext != ".vdb") throw std::runtime_error(args.output + ": unknown volume format (use .vdb)");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitBadInput;
  }
  Scene scene;
  int object = -1;
  try {
    SceneDesc desc = load_scene_file(args.scene, args.sets);
    object = vdb_export_object(desc, args.object);
    // The export needs the objects' functions and media, not the renderer's majorants.
    desc.integrator.tracking.octree_depth = 0;
    desc.integrator.tracking.majorant_source = TrackingSettings::MajorantSource::Bound;
    scene = compile_scene(desc);
  } catch (const SceneError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitBadInput;
  }
  const bool show_progress = !args.quiet && isatty(fileno(stderr));
  const auto start = std::chrono::steady_clock::now();
  BuildMonitor monitor;
  monitor.cancel = [] { return g_signal.load() != 0; };
  // The fraction 1 comes once the grid is built, before it is written: from then on a signal
  // removes the temporary file and ends the process (catch_stop_signals).
  monitor.progress = [&](double f) {
    if (f >= 1) g_writing = true;
    if (show_progress)
      print_progress(
          "export", f,
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  };
  VdbExportResult result;
  try {
    result = export_vdb(scene, object, args.voxel_size, args.output, monitor);
  } catch (const std::invalid_argument& e) {
    if (show_progress) std::fprintf(stderr, "\n");
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitBadInput;
  }
  g_writing = false;
  if (show_progress) std::fprintf(stderr, "\n");
  if (result.cancelled) {
    const int sig = g_signal.load();
    std::fprintf(stderr, "nimbus: stopped by %s while building the grid; nothing written\n",
                 signal_name(sig));
    return 128 + sig;
  }
  if (!args.quiet)
    std::fprintf(stderr,
                 "nimbus: object %d: %llu active voxels of size %g, largest density %.4g, in %.2f "
                 "s -> %s\n",
                 object, static_cast<unsigned long long>(result.active_voxels), args.voxel_size,
                 result.max_density,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                 args.output.c_str());
  return 0;
}

}  // namespace

// An integer option's check that says its range in words: "--spp must be >= 1, not 0". (CLI11's
// own range checks print the double bounds of the option's type.)
CLI::Validator integer_in(long long lo, long long hi = std::numeric_limits<int>::max()) {
  return CLI::Validator(
      [lo, hi](std::string& value) -> std::string {
        long long x = 0;
        size_t used = 0;
        try {
          x = std::stoll(value, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == 0 || used != value.size())
          return fmt::format("must be a whole number, not \"{}\"", value);
        if (x < lo) return fmt::format("must be >= {}, not {}", lo, x);
        if (x > hi) return fmt::format("must be <= {}, not {}", hi, x);
        return {};
      },
      fmt::format("INT >= {}", lo));
}

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
      ->check(integer_in(1));
  render->add_option("--seed", args.seed, "Random seed (overrides integrator.seed)")
      ->check(integer_in(0, std::numeric_limits<long long>::max()));
  render->add_option("--threads", args.threads, "Worker threads (default: all cores)")
      ->check(integer_in(1, 4096));
  render->add_option("--set", args.sets,
                     "Override a scene key: --set integrator.spp=16 (dotted path, JSON value); "
                     "repeatable");
  render->add_option("--stats", args.stats, "Write render statistics as JSON to this file");
  render->add_option("--max-memory", args.max_memory,
                     "Refuse renders estimated to need more memory than this (e.g. 8G, 512M; "
                     "default: the system's available memory)");
  render->add_flag("-q,--quiet", args.quiet, "Print nothing but errors");

  ExperimentArgs exp;
  std::string names;
  for (const auto& e : nimbus::experiments()) names += "\n  " + e.name + ": " + e.description;
  CLI::App* experiment = app.add_subcommand(
      "experiment",
      "Run a paper-reproduction experiment (docs/reproduction.md): CSV, plots, images");
  experiment->add_option("name", exp.name, "Experiment:" + names)->required();
  experiment->add_option("--out", exp.out, "Directory for the results (created if missing)")
      ->required();
  experiment->add_flag("--quick", exp.quick, "A tiny variant that runs in seconds");
  experiment->add_option("--seed", exp.seed, "Random seed")
      ->check(integer_in(0, std::numeric_limits<long long>::max()));
  experiment->add_option("--threads", exp.threads, "Worker threads (default: all cores)")
      ->check(integer_in(1, 4096));
  experiment->add_option("--scenes", exp.scenes, "Directory of the scene files")
      ->capture_default_str();
  experiment->add_flag("--no-plot", exp.no_plot, "Write the CSV files only");

  ExportArgs exp_vdb;
  CLI::App* export_vdb = app.add_subcommand(
      "export-vdb", "Write an object's medium as an OpenVDB fog volume (docs/cli.md)");
  export_vdb->add_option("scene", exp_vdb.scene, "Scene file (JSON)")->required();
  export_vdb->add_option("-o,--output", exp_vdb.output, "Output file (.vdb)")->required();
  export_vdb->add_option("--voxel-size", exp_vdb.voxel_size, "Voxel size H in world units (> 0)")
      ->required();
  export_vdb
      ->add_option("--object", exp_vdb.object,
                   "Index into the scene's objects (default: the first with a medium)")
      ->check(integer_in(0));
  export_vdb->add_option("--set", exp_vdb.sets, "Override a scene key, as for render; repeatable");
  export_vdb->add_flag("-q,--quiet", exp_vdb.quiet, "Print nothing but errors");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitBadInput;
  }
  try {
    if (experiment->parsed()) return run_experiment(exp);
    catch_stop_signals();
    if (export_vdb->parsed()) return run_export_vdb(exp_vdb);
    return run_render(args);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitFailure;
  }
}
