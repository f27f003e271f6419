// `nimbus experiment NAME --out DIR`: a paper-reproduction experiment (experiments/), its CSV
// files, and plots when tools/plot_NAME.py and matplotlib are there.

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <system_error>

#include "command.h"
#include "nimbus/experiments/experiment.h"
#include "nimbus/scene/json_reader.h"
#include "options.h"

namespace {

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

}  // namespace

Command experiment_command(CLI::App& app) {
  const auto args = std::make_shared<ExperimentArgs>();
  std::string names;
  for (const auto& e : nimbus::experiments()) names += "\n  " + e.name + ": " + e.description;
  CLI::App* experiment = app.add_subcommand(
      "experiment",
      "Run a paper-reproduction experiment (docs/reproduction.md): CSV, plots, images");
  experiment->add_option("name", args->name, "Experiment:" + names)->required();
  experiment->add_option("--out", args->out, "Directory for the results (created if missing)")
      ->required();
  experiment->add_flag("--quick", args->quick, "A tiny variant that runs in seconds");
  experiment->add_option("--seed", args->seed, "Random seed")
      ->check(integer_in(0, std::numeric_limits<long long>::max()));
  experiment->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->check(integer_in(1, 4096));
  experiment->add_option("--scenes", args->scenes, "Directory of the scene files")
      ->capture_default_str();
  experiment->add_flag("--no-plot", args->no_plot, "Write the CSV files only");
  return {experiment, [args](const Cluster&) { return run_experiment(*args); }};
}
