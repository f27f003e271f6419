// The nimbus command line: `nimbus render SCENE ...`, `nimbus experiment NAME --out DIR` and
// `nimbus export-vdb SCENE -o OUT.vdb --voxel-size H`.

#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "nimbus/experiments/experiment.h"
#include "nimbus/io/atomic_file.h"
#include "nimbus/io/film_image.h"
#include "nimbus/io/output.h"
#include "nimbus/io/vdb_export.h"
#include "nimbus/job/checkpoint.h"
#include "nimbus/job/fingerprint.h"
#include "nimbus/render/memory_estimate.h"
#include "nimbus/render/path_spectra.h"
#include "nimbus/render/renderer.h"
#include "nimbus/render/stats.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "render_job.h"

namespace {

constexpr int kExitFailure = 1;
constexpr int kExitBadInput = 2;

struct RenderArgs {
  std::string scene;
  std::vector<std::string> outputs;
  std::vector<std::string> sets;
  int spp = 0;
  std::optional<uint64_t> seed;
  int threads = 0;
  std::string stats;
  std::optional<std::string> max_memory;  // none: the system's available memory
  bool quiet = false;
  std::string checkpoint;
  double checkpoint_interval = 0;  // 0: not given (60 s)
  std::string resume;
};

// SIGINT, SIGTERM and SIGHUP: the first one during a render stops it before its next pixel
// (exit 128 + the signal's number; nothing is written, or with checkpoints the checkpoint and
// the image so far); during writing, or a second one, removes every temporary file and ends the
// process by the signal at once.
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

// A step's outcome: exit code 0 (go on), or the code and the one line to print.
struct Outcome {
  int code = 0;
  std::string message;
};

// Refuses, with one line and exit 2, a render that the machine (or --max-memory) cannot hold,
// before anything large is allocated (render/memory_estimate.h).
Outcome check_memory(const nimbus::SceneDesc& desc, const RenderArgs& args) {
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
    if (args.max_memory) {
      limit = parse_memory_size(*args.max_memory);
      source = "allowed by --max-memory";
    } else {
      limit = available_memory();
    }
  } catch (const std::invalid_argument& e) {
    return {kExitBadInput, fmt::format("nimbus: --max-memory: {}", e.what())};
  }
  if (limit > 0 && need.total() > double(limit))
    return {kExitBadInput,
            fmt::format("nimbus: the render needs about {} (film {}, image {}, majorant octrees "
                        "{}), more than the {} {}",
                        format_memory(need.total()), format_memory(need.film),
                        format_memory(need.image), format_memory(need.octrees),
                        format_memory(double(limit)), source)};
  return {};
}

// The files a run reads: the scene file and every file its description made the loader read.
std::vector<nimbus::NamedFile> scene_inputs(const std::string& scene,
                                            const nimbus::SceneDesc& desc) {
  std::vector<nimbus::NamedFile> inputs = {{"the scene file", scene}};
  for (const nimbus::InputFile& f : desc.inputs)
    inputs.push_back({"the file of " + f.pointer, f.path});
  return inputs;
}

// Refuses a render whose outputs would overwrite what it reads or each other (issue 29: --stats
// s.json replaced the scene). --resume's file is read, and is written again by the later
// checkpoints unless --checkpoint names another file.
void check_render_files(const RenderArgs& args, const std::vector<std::string>& outputs,
                        const nimbus::SceneDesc& desc) {
  using nimbus::NamedFile;
  std::vector<NamedFile> written, read = scene_inputs(args.scene, desc);
  for (const std::string& out : outputs) written.push_back({"-o", out});
  if (!args.stats.empty()) written.push_back({"--stats", args.stats});
  if (!args.checkpoint.empty()) {
    written.push_back({"--checkpoint", args.checkpoint});
    if (!args.resume.empty() && !nimbus::same_file(args.resume, args.checkpoint))
      read.push_back({"the checkpoint of --resume", args.resume});
  } else if (!args.resume.empty()) {
    written.push_back({"--resume (its later checkpoints)", args.resume});
  }
  nimbus::check_outputs_distinct(written, read);
}

// Under mpirun every rank runs each step and all agree on its outcome (cluster_agree): a
// failure is printed once, by rank 0, and every rank exits with its code. Returns that code.
int agree(const Cluster& cluster, const Outcome& mine) {
  const ClusterFailure f = cluster_agree(mine.code, mine.message);
  if (f.code != 0 && cluster.rank == 0)
    std::fprintf(
        stderr, "%s\n",
        nimbus::printable_line(f.rank == 0 ? f.message
                                           : fmt::format("nimbus: rank {}: {}", f.rank, f.message))
            .c_str());
  return f.code;
}

// The render's inputs once every rank has agreed that they are good.
struct Prepared {
  std::vector<std::string> outputs;
  std::vector<std::string> overrides;
  std::string checkpoint;      // where checkpoints go; empty: none
  nimbus::Checkpoint resumed;  // --resume's checkpoint (rank 0)
  nimbus::SceneDesc desc;
};

// Rank 0 alone checks the outputs and reads the checkpoint to resume (the other ranks write
// and read nothing); every rank loads the scene.
Outcome prepare(const RenderArgs& args, const Cluster& cluster, Prepared& p) {
  using namespace nimbus;
  const bool lead = cluster.rank == 0;
  p.overrides = args.sets;
  p.checkpoint = !args.checkpoint.empty() ? args.checkpoint : args.resume;
  if (args.checkpoint_interval > 0 && p.checkpoint.empty())
    return {kExitBadInput, "nimbus: --checkpoint-interval needs --checkpoint or --resume"};
  int spp = args.spp;
  Outcome resume_failed;
  if (lead && !args.resume.empty()) {
    try {
      p.resumed = load_checkpoint(args.resume);
      // Without --spp a resumed render finishes what the checkpoint's render was asked for.
      if (spp == 0) spp = p.resumed.spp;
    } catch (const std::exception& e) {
      resume_failed = {kExitBadInput, fmt::format("nimbus: --resume: {}", e.what())};
    }
  }
  // Every rank renders with rank 0's spp: a pixel's samples depend on it (integrator.sampler
  // "zsobol"), and only rank 0 reads the checkpoint.
  if (!args.resume.empty()) spp = int(cluster_broadcast(uint64_t(spp)));
  if (resume_failed.code != 0) return resume_failed;
  if (spp > 0) p.overrides.push_back(fmt::format("integrator.spp={}", spp));
  if (args.seed) p.overrides.push_back(fmt::format("integrator.seed={}", *args.seed));

  p.outputs = args.outputs;
  if (p.outputs.empty()) {
    const std::string stem = std::filesystem::path(args.scene).stem().string();
    p.outputs = {stem + ".exr", stem + ".png"};
  }
  if (lead) try {
      for (const std::string& out : p.outputs) check_output_path(out);
      if (!args.stats.empty()) check_writable_path(args.stats);
      if (!p.checkpoint.empty()) check_writable_path(p.checkpoint);
    } catch (const std::exception& e) {
      return {kExitBadInput, fmt::format("nimbus: {}", e.what())};
    }
  try {
    p.desc = load_scene_file(args.scene, p.overrides);
  } catch (const SceneError& e) {
    return {kExitBadInput, e.what()};
  }
  if (lead) try {
      check_render_files(args, p.outputs, p.desc);
    } catch (const std::exception& e) {
      return {kExitBadInput, fmt::format("nimbus: {}", e.what())};
    }
  if (lead && !args.resume.empty()) {
    const std::string diff = fingerprint_difference(
        p.resumed.fingerprint, render_fingerprint(args.scene, p.overrides, p.desc.inputs));
    if (!diff.empty())
      return {kExitBadInput,
              fmt::format("nimbus: --resume {}: the checkpoint is of another scene or other "
                          "settings ({})",
                          args.resume, diff)};
    if (p.resumed.film.width != p.desc.film.width || p.resumed.film.height != p.desc.film.height)
      return {kExitBadInput, fmt::format("nimbus: --resume {}: a film of {}x{} pixels, the "
                                         "scene's image is {}x{}",
                                         args.resume, p.resumed.film.width, p.resumed.film.height,
                                         p.desc.film.width, p.desc.film.height)};
    const uint32_t most =
        *std::max_element(p.resumed.film.samples.begin(), p.resumed.film.samples.end());
    if (most > uint32_t(p.desc.integrator.spp))
      return {kExitBadInput, fmt::format("nimbus: --resume {}: pixels of the checkpoint hold {} "
                                         "samples, more than --spp {}",
                                         args.resume, most, p.desc.integrator.spp)};
  }
  return check_memory(p.desc, args);
}

// Every rank compiles the scene and builds its own majorant octrees; they must be the same bits
// on every rank (and, on resume, those of the checkpoint's render).
Outcome compile(const Prepared& p, bool show_progress, nimbus::Scene& scene) {
  using namespace nimbus;
  // The majorant octrees can take seconds to build (deep trees, sampled bounds): they get a
  // bar of their own, and a signal stops them too.
  BuildMonitor monitor;
  monitor.cancel = [] { return g_signal.load() != 0; };
  if (show_progress) monitor.progress = progress_bar("octrees");
  try {
    scene = compile_scene(p.desc, monitor);
  } catch (const SceneError& e) {
    if (show_progress) std::fprintf(stderr, "\n");
    return {kExitBadInput, e.what()};
  }
  if (show_progress) std::fprintf(stderr, "\n");
  if (const int sig = g_signal.load(); sig != 0)
    return {128 + sig,
            fmt::format("nimbus: stopped by {} while building the majorant octrees; nothing "
                        "written",
                        signal_name(sig))};
  return {};
}

// The checks of the octrees after compile: equal on every rank (a collective call).
Outcome check_majorants(const Cluster& cluster, const Prepared& p, const RenderArgs& args,
                        uint64_t mine) {
  const uint64_t lead = cluster_broadcast(mine);
  if (mine != lead)
    return {1, fmt::format("built majorant octrees that differ from rank 0's (hash {:016x}, "
                           "rank 0 {:016x}): are all ranks running the same nimbus?",
                           mine, lead)};
  if (cluster.rank == 0 && !args.resume.empty() && p.resumed.majorants != mine)
    return {kExitBadInput, fmt::format("nimbus: --resume {}: the checkpoint's majorant octrees "
                                       "differ from this render's (another nimbus build?)",
                                       args.resume)};
  return {};
}

// Writes every output as one transaction (io/atomic_file.h): all of them, or none.
int write_outputs(const RenderArgs& args, const std::vector<std::string>& outputs,
                  const nimbus::Scene& scene, const nimbus::RenderResult& result,
                  const nlohmann::json& extra_stats) {
  using namespace nimbus;
  g_writing = true;
  try {
    OutputTransaction outputs_of_this_run;
    const Image image = to_image(result.film);
    for (const std::string& out : outputs) write_image(out, image);
    if (!args.stats.empty()) {
      nlohmann::json stats = render_stats(scene, result, args.scene);
      if (extra_stats.is_object()) stats.update(extra_stats);
      const std::string text = stats.dump(2) + "\n";
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
  return 0;
}

void warn_rejected(const nimbus::Counters& counters) {
  if (const uint64_t n = counters.rejected_samples; n > 0)
    std::fprintf(stderr,
                 "nimbus: warning: %llu samples were NaN or infinite and counted as 0 "
                 "(counters.rejected_samples in --stats)\n",
                 static_cast<unsigned long long>(n));
}

std::string joined(const std::vector<std::string>& list) {
  std::string s;
  for (const auto& o : list) s += (s.empty() ? "" : ", ") + o;
  return s;
}

// The render in one call, in this process: no checkpoints, no other ranks.
int render_at_once(const RenderArgs& args, const Prepared& p, const nimbus::Scene& scene,
                   bool show_progress) {
  using namespace nimbus;
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
  warn_rejected(result.counters);
  if (const int failed = write_outputs(args, p.outputs, scene, result, {}); failed != 0)
    return failed;
  if (!args.quiet) {
    const double samples =
        double(scene.settings.width) * scene.settings.height * scene.settings.spp;
    std::fprintf(stderr, "nimbus: %dx%d, %d spp in %.2f s (%.3g samples/s, %d threads) -> %s\n",
                 scene.settings.width, scene.settings.height, scene.settings.spp, result.seconds,
                 samples / result.seconds, result.threads, joined(p.outputs).c_str());
  }
  return 0;
}

// Rank 0 of a render job (apps/render_job.h): under mpirun, or with --checkpoint or --resume.
int lead_render_job(const RenderArgs& args, const Cluster& cluster, const Prepared& p,
                    const nimbus::Scene& scene, bool show_progress) {
  using namespace nimbus;
  JobSettings job;
  job.spp = scene.settings.spp;
  job.threads = args.threads;
  job.start =
      args.resume.empty() ? Film(scene.settings.width, scene.settings.height) : p.resumed.film;
  const uint64_t held_at_start = samples_held(job.start);
  // Why the last checkpoint could not be saved; empty: it was, or none was due. Reported in the
  // run's last line, never as written.
  auto checkpoint_failure = std::make_shared<std::string>();
  if (!p.checkpoint.empty()) {
    Checkpoint header;
    header.fingerprint = render_fingerprint(args.scene, p.overrides, p.desc.inputs);
    header.majorants = majorant_hash(scene);
    header.spp = scene.settings.spp;
    job.checkpoint_interval = args.checkpoint_interval > 0 ? args.checkpoint_interval : 60;
    // Units are short next to the interval, so checkpoints come on time.
    job.unit_seconds = std::min(job.unit_seconds, job.checkpoint_interval / 4);
    job.checkpoint = [header, path = p.checkpoint, held_at_start,
                      checkpoint_failure](const Film& film) mutable {
      // Nothing rendered yet: the file would gain nothing, and a fresh render's checkpoint
      // would replace an earlier one with an empty film.
      if (samples_held(film) == held_at_start) return;
      header.film = film;
      try {
        save_checkpoint(header, path);
        checkpoint_failure->clear();
      } catch (const std::exception& e) {
        *checkpoint_failure = e.what();
        std::fprintf(stderr, "\nnimbus: warning: --checkpoint: %s (not saved)\n", e.what());
      }
    };
  }
  if (show_progress) job.progress = progress_bar("render");
  job.stop = [] { return g_signal.load() != 0; };
  const JobResult r = lead_job(scene, cluster, std::move(job));
  if (show_progress) std::fprintf(stderr, "\n");
  const int sig = g_signal.load();
  // Stopped without a checkpoint: as a render in one call, nothing is written. With one, the
  // film holds whole units only, and its image so far is written too.
  if (r.stopped && p.checkpoint.empty()) {
    std::fprintf(stderr, "nimbus: stopped by %s before the render finished; nothing written\n",
                 signal_name(sig));
    return 128 + sig;
  }
  // Stopped before a unit was done: the image so far would be the one at the start (empty for a
  // fresh render) and replace an earlier good one.
  if (r.stopped && samples_held(r.film) == held_at_start) {
    std::fprintf(stderr, "nimbus: stopped by %s before a sample was rendered; nothing written\n",
                 signal_name(sig));
    return 128 + sig;
  }
  warn_rejected(r.counters);
  RenderResult result;
  result.film = std::move(r.film);
  result.counters = r.counters;
  result.seconds = r.seconds;
  result.threads = args.threads > 0 ? args.threads : int(std::thread::hardware_concurrency());
  nlohmann::json extra;
  if (cluster.mpi)
    extra["mpi"] = {{"ranks", cluster.size}, {"samples_per_rank", r.samples_per_rank}};
  const uint64_t held = samples_held(result.film);
  if (!p.checkpoint.empty())
    extra["checkpoint"] = {
        {"file", p.checkpoint}, {"samples_at_start", held_at_start}, {"samples", held}};
  if (const int failed = write_outputs(args, p.outputs, scene, result, extra); failed != 0)
    return failed;
  const double total = double(scene.settings.width) * scene.settings.height * scene.settings.spp;
  if (r.stopped) {
    if (checkpoint_failure->empty())
      std::fprintf(stderr,
                   "nimbus: stopped by %s at %.1f%% of the samples; wrote the image so far to %s "
                   "and the checkpoint %s (continue with --resume %s)\n",
                   signal_name(sig), 100 * double(held) / total, joined(p.outputs).c_str(),
                   p.checkpoint.c_str(), p.checkpoint.c_str());
    else
      std::fprintf(stderr,
                   "nimbus: stopped by %s at %.1f%% of the samples; wrote the image so far to %s; "
                   "the checkpoint was not saved (%s)\n",
                   signal_name(sig), 100 * double(held) / total, joined(p.outputs).c_str(),
                   checkpoint_failure->c_str());
    return 128 + sig;
  }
  if (!checkpoint_failure->empty()) {
    std::fprintf(stderr,
                 "nimbus: wrote %s; the last checkpoint was not saved (%s): the render cannot be "
                 "continued from it\n",
                 joined(p.outputs).c_str(), checkpoint_failure->c_str());
    return kExitFailure;
  }
  if (!args.quiet) {
    const double samples = double(held - held_at_start);
    std::fprintf(stderr,
                 "nimbus: %dx%d, %d spp in %.2f s (%.3g samples/s, %d threads x %d %s) -> %s\n",
                 scene.settings.width, scene.settings.height, scene.settings.spp, r.seconds,
                 samples / r.seconds, result.threads, cluster.size,
                 cluster.size == 1 ? "process" : "ranks", joined(p.outputs).c_str());
  }
  return 0;
}

int run_render(const RenderArgs& args, const Cluster& cluster) {
  using namespace nimbus;
  const bool lead = cluster.rank == 0;
  Prepared p;
  if (const int code = agree(cluster, prepare(args, cluster, p)); code != 0) return code;
  const bool show_progress = lead && !args.quiet && isatty(fileno(stderr));
  Scene scene;
  if (const int code = agree(cluster, compile(p, show_progress, scene)); code != 0) return code;
  if (const int code = agree(cluster, check_majorants(cluster, p, args, majorant_hash(scene)));
      code != 0)
    return code;

  if (!cluster.mpi && p.checkpoint.empty()) return render_at_once(args, p, scene, show_progress);
  if (!lead) {
    work_on_job(scene, args.threads, [] { return g_signal.load() != 0; });
    return receive_exit_code();
  }
  const int code = lead_render_job(args, cluster, p, scene, show_progress);
  send_exit_code(cluster, code);
  return code;
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
    try {
      check_outputs_distinct({{"-o", args.output}}, scene_inputs(args.scene, desc));
    } catch (const std::runtime_error& e) {
      std::fprintf(stderr, "nimbus: %s\n", e.what());
      return kExitBadInput;
    }
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

// A whole number in [0, 2^64 - 1], the range of the scene file's integrator.seed (issue 29: the
// command line stopped at 2^63 - 1).
CLI::Validator unsigned_64() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        const bool digits = !value.empty() && value.size() <= 20 &&
                            value.find_first_not_of("0123456789") == std::string::npos;
        if (!digits) return fmt::format("must be a whole number, not \"{}\"", value);
        try {
          std::stoull(value);
        } catch (const std::out_of_range&) {
          return fmt::format("must be <= {}, not {}", std::numeric_limits<uint64_t>::max(), value);
        }
        return {};
      },
      "UINT64");
}

// A number of seconds > 0, with the check said in words, as integer_in does.
CLI::Validator positive_seconds() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        double x = 0;
        size_t used = 0;
        try {
          x = std::stod(value, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == 0 || used != value.size())
          return fmt::format("must be a number, not \"{}\"", value);
        if (!(x > 0) || !std::isfinite(x)) return fmt::format("must be > 0, not {}", value);
        return {};
      },
      "SECONDS > 0");
}

int run_command(int argc, char** argv, const Cluster& cluster) {
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
      ->check(unsigned_64());
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
  render->add_option("--checkpoint", args.checkpoint,
                     "Save the render's state to this file now and then, when it ends and when "
                     "a signal stops it (docs/cli.md)");
  render
      ->add_option("--checkpoint-interval", args.checkpoint_interval,
                   "Seconds between checkpoints (default 60)")
      ->check(positive_seconds());
  render->add_option("--resume", args.resume,
                     "Continue the render of this checkpoint up to --spp (default: the spp it "
                     "was started with); later checkpoints go to the same file unless "
                     "--checkpoint says otherwise");

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
    // Under mpirun every rank parses the same command line: rank 0 alone says what is wrong.
    if (cluster.rank != 0) return e.get_exit_code() == 0 ? 0 : kExitBadInput;
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // One line (issue 29: CLI11 adds a second, "Run with --help for more information.").
    std::fprintf(stderr, "nimbus: %s\n", nimbus::printable_line(e.what()).c_str());
    return kExitBadInput;
  }
  try {
    if (cluster.size > 1 && !render->parsed()) {
      if (cluster.rank == 0)
        std::fprintf(stderr, "nimbus: only render runs on several MPI ranks (docs/cli.md)\n");
      return kExitBadInput;
    }
    if (experiment->parsed()) return run_experiment(exp);
    catch_stop_signals();
    if (export_vdb->parsed()) return run_export_vdb(exp_vdb);
    return run_render(args, cluster);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nimbus: %s\n", nimbus::printable_line(e.what()).c_str());
    // The other ranks may be waiting for this one: end them all.
    if (cluster.size > 1) cluster_abort(kExitFailure);
    return kExitFailure;
  }
}

int main(int argc, char** argv) {
  const Cluster cluster = cluster_start(&argc, &argv);
  const int code = run_command(argc, argv, cluster);
  cluster_end();
  return code;
}
