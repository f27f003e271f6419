// The nimbus command line: `nimbus render SCENE ...`, `nimbus view SCENE`, `nimbus experiment
// NAME --out DIR` and `nimbus export-vdb SCENE -o OUT.vdb --voxel-size H`.

#include <fmt/format.h>
#include <fmt/ranges.h>
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
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cluster.h"
#include "nimbus/experiments/experiment.h"
#include "nimbus/io/atomic_file.h"
#include "nimbus/io/display_server.h"
#include "nimbus/io/film_image.h"
#include "nimbus/io/output.h"
#include "nimbus/io/vdb_export.h"
#include "nimbus/job/checkpoint.h"
#include "nimbus/job/fingerprint.h"
#include "nimbus/job/render_job.h"
#include "nimbus/render/memory_estimate.h"
#include "nimbus/render/renderer.h"
#include "nimbus/render/setting_names.h"
#include "nimbus/render/settings.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "nimbus/view/view_server.h"
#include "nimbus/view/view_session.h"

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
  std::string display_server;  // HOST:PORT of a tev viewer; "": none
  std::string aov;             // AOV names, "albedo,normal"; "": the scene's film.aov
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
// Whether a progress bar's line is open (drawn after a \r, not yet ended): a warning ends it
// first, and a render without a bar (-q, or stderr not a terminal) prints no empty lines.
// Bars and warnings come from several threads (the render's, the display server's): one at a
// time, so that a warning never lands inside a bar's line (issue 44).
std::mutex g_stderr_mutex;
bool g_bar_open = false;  // guarded by g_stderr_mutex

void end_bar_line_locked() {
  if (g_bar_open) std::fprintf(stderr, "\n");
  g_bar_open = false;
}

void end_bar_line() {
  std::lock_guard lock(g_stderr_mutex);
  end_bar_line_locked();
}

// "nimbus: warning: W" on a line of its own.
void print_warning(const std::string& w) {
  std::lock_guard lock(g_stderr_mutex);
  end_bar_line_locked();
  std::fprintf(stderr, "nimbus: warning: %s\n", nimbus::printable_line(w).c_str());
}

void print_progress(const char* what, double fraction, double elapsed) {
  std::lock_guard lock(g_stderr_mutex);
  g_bar_open = true;
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

// The objects' compile's bar: drawn only once it has taken half a second (most scenes compile
// faster), on a line of its own.
std::function<void(double)> objects_bar() {
  const auto start = std::chrono::steady_clock::now();
  return [start, drawn = false](double f) mutable {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!drawn && elapsed < 0.5) return;
    drawn = true;
    print_progress("objects", f, elapsed);
    if (f >= 1) end_bar_line();
  };
}

// A step's outcome: exit code 0 (go on), or the code and the one line to print.
struct Outcome {
  int code = 0;
  std::string message;
};

// The files a run reads: the scene file and every file compiling it read.
std::vector<nimbus::NamedFile> scene_inputs(const std::string& scene,
                                            const std::vector<nimbus::InputFile>& read) {
  std::vector<nimbus::NamedFile> inputs = {{"the scene file", scene}};
  for (const nimbus::InputFile& f : read) inputs.push_back({"the file of " + f.pointer, f.path});
  return inputs;
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

// A step of the render job as an outcome: its refusals are bad input (exit 2), one line.
template <class Step>
Outcome attempt(Step&& step) {
  try {
    step();
  } catch (const nimbus::SceneError& e) {
    return {kExitBadInput, e.what()};
  } catch (const nimbus::JobError& e) {
    return {kExitBadInput, fmt::format("nimbus: {}", e.what())};
  }
  return {};
}

// The items of "albedo,normal", empty ones included.
std::vector<std::string> comma_separated(const std::string& list) {
  std::vector<std::string> items;
  for (size_t start = 0, comma = 0; comma != std::string::npos; start = comma + 1) {
    comma = list.find(',', start);
    items.push_back(list.substr(start, comma - start));
  }
  return items;
}

// The job's options from the command line's (the parts that are the job's).
nimbus::RenderJobOptions job_options(const RenderArgs& args) {
  nimbus::RenderJobOptions o;
  o.overrides = args.sets;
  // --aov overrides film.aov, after every --set, as --spp overrides integrator.spp.
  if (!args.aov.empty())
    o.overrides.push_back("film.aov=" + nlohmann::json(comma_separated(args.aov)).dump());
  o.spp = args.spp;
  o.seed = args.seed;
  o.threads = args.threads;
  o.checkpoint = args.checkpoint;
  if (args.checkpoint_interval > 0) o.checkpoint_interval = args.checkpoint_interval;
  o.resume = args.resume;
  o.cancel = [] { return g_signal.load() != 0; };
  o.warning = print_warning;
  return o;
}

// The outputs, and the checks of the command line's own options; refuses a render whose outputs
// would overwrite what it reads or each other (issue 29: --stats s.json replaced the scene).
Outcome check_outputs(const RenderArgs& args, const nimbus::RenderJob& job,
                      const std::vector<std::string>& outputs) {
  using namespace nimbus;
  try {
    std::vector<NamedFile> written;
    for (const std::string& out : outputs) written.push_back({"-o", out});
    if (!args.stats.empty()) written.push_back({"--stats", args.stats});
    for (const NamedFile& f : job.files_written()) written.push_back(f);
    check_outputs_distinct(written, job.files_read());
  } catch (const std::exception& e) {
    return {kExitBadInput, fmt::format("nimbus: {}", e.what())};
  }
  return {};
}

// With AOVs, every output must be an EXR: a PNG cannot hold their layers.
Outcome check_aov_outputs(nimbus::AovSet aovs, const std::vector<std::string>& outputs) {
  if (aovs.empty()) return {};
  for (const std::string& out : outputs) {
    std::string ext = std::filesystem::path(out).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext != ".exr")
      return {kExitBadInput,
              fmt::format("nimbus: -o {}: AOVs (--aov, film.aov) are layers of an EXR; write the "
                          "render to an .exr",
                          out)};
  }
  return {};
}

// Writes every output as one transaction (io/atomic_file.h): all of them, or none.
int write_outputs(const RenderArgs& args, const std::vector<std::string>& outputs,
                  const nimbus::Film& film, nimbus::AovSet aovs, const nlohmann::json& stats) {
  using namespace nimbus;
  g_writing = true;
  try {
    OutputTransaction outputs_of_this_run;
    const Image image = to_image(film, aovs);
    for (const std::string& out : outputs) write_image(out, image);
    if (!args.stats.empty()) {
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

std::string joined(const std::vector<std::string>& list) {
  std::string s;
  for (const auto& o : list) s += (s.empty() ? "" : ", ") + o;
  return s;
}

// Rank 0's end of the render: what was rendered is written, or why not is said.
int finish_render(const RenderArgs& args, const nimbus::RenderJob& job,
                  const std::vector<std::string>& outputs, const nimbus::JobOutcome& r) {
  using namespace nimbus;
  const int sig = g_signal.load();
  const std::string& checkpoint = job.checkpoint_file();
  // Stopped without a checkpoint: nothing is written. With one, the film holds whole units
  // only, and its image so far is written too, unless no unit was done: the image would be the
  // one at the start (empty for a fresh render) and replace an earlier good one.
  if (r.stopped && checkpoint.empty()) {
    std::fprintf(stderr, "nimbus: stopped by %s before the render finished; nothing written\n",
                 signal_name(sig));
    return 128 + sig;
  }
  const uint64_t held = samples_held(r.film);
  if (r.stopped && held == r.samples_at_start) {
    std::fprintf(stderr, "nimbus: stopped by %s before a sample was rendered; nothing written\n",
                 signal_name(sig));
    return 128 + sig;
  }
  if (const uint64_t n = r.counters.rejected_samples; n > 0)
    std::fprintf(stderr,
                 "nimbus: warning: %llu samples were NaN or of magnitude %.3g or more and "
                 "counted as 0 (counters.rejected_samples in --stats)\n",
                 static_cast<unsigned long long>(n), r.film.max_value());
  if (const int failed =
          write_outputs(args, outputs, r.film, job.scene().settings.aovs, job.stats(r));
      failed != 0)
    return failed;
  const RenderSettings& s = job.scene().settings;
  if (r.stopped) {
    const double done = 100 * double(held) / (double(s.width) * s.height * s.spp);
    if (r.checkpoint_failure.empty())
      std::fprintf(stderr,
                   "nimbus: stopped by %s at %.1f%% of the samples; wrote the image so far to %s "
                   "and the checkpoint %s (continue with --resume %s)\n",
                   signal_name(sig), done, joined(outputs).c_str(), checkpoint.c_str(),
                   checkpoint.c_str());
    else
      std::fprintf(stderr,
                   "nimbus: stopped by %s at %.1f%% of the samples; wrote the image so far to %s; "
                   "the checkpoint was not saved (%s)\n",
                   signal_name(sig), done, joined(outputs).c_str(), r.checkpoint_failure.c_str());
    return 128 + sig;
  }
  if (!r.checkpoint_failure.empty()) {
    std::fprintf(stderr,
                 "nimbus: wrote %s; the last checkpoint was not saved (%s): the render cannot be "
                 "continued from it\n",
                 joined(outputs).c_str(), r.checkpoint_failure.c_str());
    return kExitFailure;
  }
  if (!args.quiet)
    std::fprintf(stderr, "nimbus: %s -> %s\n", job.summary(r).c_str(), joined(outputs).c_str());
  return 0;
}

// After the job, rank 0 tells every other rank its exit code; they wait for it.
constexpr int kExitTag = 3;

void send_exit_code(const Cluster& cluster, int code) {
  const int32_t c = code;
  for (int r = 1; r < cluster.size; ++r) cluster_send(r, kExitTag, std::as_bytes(std::span(&c, 1)));
}

int receive_exit_code() {
  const ClusterMessage m = cluster_receive(0, kExitTag);
  int32_t c = kExitFailure;
  if (m.bytes.size() == sizeof c) std::memcpy(&c, m.bytes.data(), sizeof c);
  return c;
}

// `nimbus render`: the library's render job (nimbus/job/render_job.h), its steps agreed on by
// every rank under mpirun. Rank 0 alone reads the checkpoint to resume and checks the outputs
// (the other ranks write and read nothing); every rank loads and compiles the scene and builds
// its own majorant octrees, which must be the same bits on every rank.
int run_render(const RenderArgs& args, const Cluster& cluster) {
  using namespace nimbus;
  const bool lead = cluster.rank == 0;
  if (args.checkpoint_interval > 0 && args.checkpoint.empty() && args.resume.empty())
    return agree(cluster,
                 {kExitBadInput, "nimbus: --checkpoint-interval needs --checkpoint or --resume"});
  RenderJobOptions options = job_options(args);
  if (args.max_memory) {
    try {
      options.max_memory = parse_memory_size(*args.max_memory);
    } catch (const std::invalid_argument& e) {
      return agree(cluster, {kExitBadInput, fmt::format("nimbus: --max-memory: {}", e.what())});
    }
  }
  const bool show_progress = lead && !args.quiet && isatty(fileno(stderr));
  if (show_progress) options.progress = progress_bar("render");
  // The render shown in tev as it refines (io/display_server.h): rank 0's film.
  std::unique_ptr<DisplayServer> display;
  if (!args.display_server.empty()) {
    Outcome address;
    if (lead) {
      const std::string name =
          std::filesystem::path(args.outputs.empty() ? args.scene : args.outputs.front())
              .filename()
              .string();
      try {
        display = std::make_unique<DisplayServer>(args.display_server, name, options.warning);
        options.display = [&display](const Film& film) { display->update(film); };
      } catch (const std::invalid_argument& e) {
        address = {kExitBadInput, fmt::format("nimbus: {}", e.what())};
      }
    }
    if (const int code = agree(cluster, address); code != 0) return code;
  }
  RenderJob job(options);

  int spp = args.spp;
  Outcome step;
  if (lead) step = attempt([&] { spp = job.read_resume(); });
  // Every rank renders with rank 0's spp: a pixel's samples depend on it (integrator.sampler
  // "zsobol"), and only rank 0 reads the checkpoint.
  if (!args.resume.empty()) spp = int(cluster_broadcast(uint64_t(spp)));
  if (const int code = agree(cluster, step); code != 0) return code;

  std::vector<std::string> outputs = args.outputs;
  const std::string stem = std::filesystem::path(args.scene).stem().string();
  if (outputs.empty()) outputs = {stem + ".exr", stem + ".png"};
  if (lead) try {
      for (const std::string& out : outputs) check_output_path(out);
      if (!args.stats.empty()) check_writable_path(args.stats);
      if (!job.checkpoint_file().empty()) check_writable_path(job.checkpoint_file());
    } catch (const std::exception& e) {
      step = {kExitBadInput, fmt::format("nimbus: {}", e.what())};
    }
  if (step.code == 0) step = attempt([&] { job.load(args.scene, spp); });
  // AOVs are layers of an EXR: the default outputs are then the EXR alone.
  const AovSet aovs = step.code == 0 ? job.description().settings.aovs : AovSet{};
  if (!aovs.empty() && args.outputs.empty()) outputs = {stem + ".exr"};
  if (lead && step.code == 0) step = check_aov_outputs(aovs, outputs);
  if (lead && step.code == 0) step = attempt([&] { job.check(); });
  if (const int code = agree(cluster, step); code != 0) return code;

  // Compiling can take seconds (many free forms; deep octrees, sampled bounds): the octrees get
  // a bar of their own, and a signal stops the objects' compile and the octrees' build too.
  BuildMonitor monitor;
  monitor.cancel = options.cancel;
  if (show_progress) {
    monitor.objects = objects_bar();
    monitor.progress = progress_bar("octrees");
  }
  bool compiled = false;
  step = attempt([&] { compiled = job.compile(monitor); });
  end_bar_line();
  if (step.code == 0 && !compiled) {
    const int sig = g_signal.load();
    step = {128 + sig, fmt::format("nimbus: stopped by {} while compiling the scene; "
                                   "nothing written",
                                   signal_name(sig))};
  }
  if (const int code = agree(cluster, step); code != 0) return code;
  if (lead)  // every rank compiles the same scene: one warning each, from the lead
    for (const std::string& w : job.scene().warnings) options.warning(w);
  const uint64_t mine = majorant_hash(job.scene()), first = cluster_broadcast(mine);
  if (mine != first)
    step = {kExitFailure, fmt::format("built majorant octrees that differ from rank 0's (hash "
                                      "{:016x}, rank 0 {:016x}): are all ranks running the same "
                                      "nimbus?",
                                      mine, first)};
  else if (lead)
    step = attempt([&] { job.check_compiled(); });
  // The files the scene read are known once it is compiled (VDB grids).
  if (lead && step.code == 0) step = check_outputs(args, job, outputs);
  if (const int code = agree(cluster, step); code != 0) return code;

  ClusterChannel channel(cluster);
  if (!lead) {
    job.work(channel);
    return receive_exit_code();
  }
  const JobOutcome r = job.run(cluster.mpi ? &channel : nullptr);
  if (display) display->finish(r.film);
  end_bar_line();
  const int code = finish_render(args, job, outputs, r);
  send_exit_code(cluster, code);
  return code;
}

struct ViewArgs {
  std::string scene;
  std::string host = "127.0.0.1";
  int port = 8080;
  std::vector<std::string> sets;
  int spp = 0;
  std::optional<uint64_t> seed;
  int threads = 0;
  std::optional<std::string> max_memory;
  bool allow_remote = false;
};

// Ends `nimbus view` once a signal has come: stops the server at once, and ends the process
// after a grace time even if the render thread does not finish (a scene load stuck in a file
// that never answers, say), as the signal asked. Destroyed, it waits for nothing more.
class ViewSignalWatcher {
 public:
  ViewSignalWatcher() : thread_([this] { watch(); }) {}
  ~ViewSignalWatcher() {
    {
      std::lock_guard lock(mutex_);
      finished_ = true;
    }
    thread_.join();
  }
  void serving(nimbus::ViewServer* server) {
    std::lock_guard lock(mutex_);
    server_ = server;
    if (server_ && g_signal.load() != 0) server_->stop();
  }

 private:
  void watch() {
    for (;;) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      std::lock_guard lock(mutex_);
      if (finished_) return;
      if (g_signal.load() != 0) break;
    }
    serving(server_);
    constexpr auto kGrace = std::chrono::seconds(2);
    const auto end = std::chrono::steady_clock::now() + kGrace;
    while (std::chrono::steady_clock::now() < end) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      std::lock_guard lock(mutex_);
      if (finished_) return;
    }
    std::fflush(stdout);
    std::_Exit(0);
  }

  std::mutex mutex_;
  nimbus::ViewServer* server_ = nullptr;
  bool finished_ = false;
  std::thread thread_;
};

// `nimbus view`: the scene rendered progressively in a web page (view/view_server.h) until a
// signal stops the server (exit 0).
int run_view(const ViewArgs& args) {
  using namespace nimbus;
  ViewOptions options;
  options.scene = args.scene;
  options.overrides = args.sets;
  options.spp = args.spp;
  options.seed = args.seed;
  options.threads = args.threads;
  if (args.max_memory) {
    try {
      options.max_memory = parse_memory_size(*args.max_memory);
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "nimbus: --max-memory: %s\n", e.what());
      return kExitBadInput;
    }
  }
  ViewServerOptions server_options;
  server_options.host = args.host;
  server_options.port = args.port;
  server_options.name = std::filesystem::path(args.scene).stem().string();
  server_options.allow_remote = args.allow_remote;
  // Declared first, destroyed last: it watches the session's load and its end too.
  ViewSignalWatcher watcher;
  std::unique_ptr<ViewSession> session;
  try {
    session = std::make_unique<ViewSession>(options);
  } catch (const std::exception& e) {
    if (g_signal.load() != 0) return 0;
    std::fprintf(stderr, "nimbus: %s\n", printable_line(e.what()).c_str());
    return kExitBadInput;
  }
  ViewServer server(*session, server_options);
  int port = 0;
  try {
    port = server.bind();
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "nimbus: %s\n", printable_line(e.what()).c_str());
    return kExitBadInput;
  }
  const bool v6 = args.host.find(':') != std::string::npos;
  const std::string address =
      fmt::format("{}{}{}:{}", v6 ? "[" : "", args.host, v6 ? "]" : "", port);
  if (!server.loopback())
    std::fprintf(stderr,
                 "nimbus: warning: serving beyond this machine (--allow-remote): anyone who "
                 "reaches %s sees the scene and can move the camera\n",
                 address.c_str());
  std::printf("nimbus view: http://%s/ (Ctrl-C stops)\n", address.c_str());
  std::fflush(stdout);
  watcher.serving(&server);
  server.serve();
  watcher.serving(nullptr);
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
    desc.settings.tracking.octree_depth = 0;
    desc.settings.tracking.majorant_source = TrackingSettings::MajorantSource::Bound;
    std::vector<InputFile> read;
    scene = compile_scene(desc, {}, &read);
    object = vdb_export_compiled(scene, object);
    try {
      check_outputs_distinct({{"-o", args.output}}, scene_inputs(args.scene, read));
    } catch (const std::runtime_error& e) {
      std::fprintf(stderr, "nimbus: %s\n", e.what());
      return kExitBadInput;
    }
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
    end_bar_line();
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitBadInput;
  }
  g_writing = false;
  end_bar_line();
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

// `nimbus settings`: every render setting (render/settings.h), or one section's Markdown table.
int list_settings(const std::string& markdown_section) {
  using namespace nimbus;
  if (!markdown_section.empty()) {
    std::fputs(settings_markdown(markdown_section).c_str(), stdout);
    return 0;
  }
  const RenderSettings defaults;
  for (const Setting& s : render_settings())
    std::printf("%-28s %-18s %s\n", std::string(s.key).c_str(), s.get(defaults).dump().c_str(),
                std::string(s.doc).c_str());
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

// export-vdb's voxel size, in the range that OpenVDB and a reader of the file accept
// (io/vdb_export.h), checked before the scene is read.
CLI::Validator voxel_size() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        // strtod, not stod: a number past a double's range (1e999, 1e-400) is out of range
        // rather than "not a number".
        char* end = nullptr;
        const double x = std::strtod(value.c_str(), &end);
        if (value.empty() || end != value.c_str() + value.size())
          return fmt::format("must be a number, not \"{}\"", value);
        if (nimbus::vdb_voxel_size_problem(x).empty()) return {};
        return fmt::format("must be in [{:g}, {:g}], not {}", nimbus::kVdbExportMinVoxelSize,
                           nimbus::kVdbExportMaxVoxelSize, value);
      },
      "H");
}

// --display-server's HOST:PORT (io/display_server.h), checked before the scene is read: an
// empty address, a missing port or an IPv6 address outside brackets is a usage error.
CLI::Validator display_address() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        try {
          nimbus::parse_display_address(value);
        } catch (const std::invalid_argument& e) {
          return e.what();
        }
        return {};
      },
      "HOST:PORT");
}

// --aov's list, "albedo,normal": names of AOVs (render/setting_names.h), none twice.
CLI::Validator aov_names() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        std::vector<std::string> known, seen;
        for (const auto& entry : nimbus::kAovNames) known.emplace_back(entry.first);
        for (const std::string& name : comma_separated(value)) {
          if (std::find(known.begin(), known.end(), name) == known.end())
            return fmt::format("unknown AOV \"{}\" (one of: {})", name, fmt::join(known, ", "));
          if (std::find(seen.begin(), seen.end(), name) != seen.end())
            return fmt::format("names \"{}\" twice", name);
          seen.push_back(name);
        }
        return {};
      },
      "albedo,normal,depth,variance");
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
  render
      ->add_option("--aov", args.aov,
                   "Write these layers into the EXR beside the colour, for denoisers: a "
                   "comma-separated list of albedo, normal, depth, variance (overrides film.aov; "
                   "docs/cli.md)")
      ->check(aov_names());
  render
      ->add_option("--display-server", args.display_server,
                   "Stream the render to a tev viewer at HOST:PORT as it refines (docs/cli.md)")
      ->check(display_address());
  render->add_option("--resume", args.resume,
                     "Continue the render of this checkpoint up to --spp (default: the spp it "
                     "was started with); later checkpoints go to the same file unless "
                     "--checkpoint says otherwise");

  ViewArgs view_args;
  CLI::App* view = app.add_subcommand(
      "view", "Render a scene progressively in a web page, with camera moves and live reloads");
  view->add_option("scene", view_args.scene, "Scene file (JSON), rendered again when saved")
      ->required();
  view->add_option("--port", view_args.port, "Port to serve on (0: any free port; default 8080)")
      ->check(integer_in(0, 65535));
  view->add_option("--host", view_args.host,
                   "Address to serve on (default 127.0.0.1: this machine only; any other "
                   "than a loopback address needs --allow-remote)");
  view->add_flag("--allow-remote", view_args.allow_remote,
                 "Allow a --host beyond the loopback: anyone who reaches it sees the scene and "
                 "can move the camera");
  view->add_option("--spp", view_args.spp, "Samples per pixel to refine to (default: the scene's)")
      ->check(integer_in(1));
  view->add_option("--seed", view_args.seed, "Random seed (overrides integrator.seed)")
      ->check(unsigned_64());
  view->add_option("--threads", view_args.threads, "Worker threads (default: all cores)")
      ->check(integer_in(1, 4096));
  view->add_option("--set", view_args.sets, "Override a scene key, as for render; repeatable");
  view->add_option("--max-memory", view_args.max_memory,
                   "Refuse scenes estimated to need more memory than this (as for render)");

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

  std::string markdown_section;
  CLI::App* settings = app.add_subcommand(
      "settings", "List the render settings of the scene format: key, type, default, meaning");
  settings
      ->add_option("--markdown", markdown_section,
                   "Print the Markdown table of one section (film, integrator, spectrum), as "
                   "docs/scene-format.md holds it")
      ->check(CLI::IsMember({"film", "integrator", "spectrum"}));

  ExportArgs exp_vdb;
  CLI::App* export_vdb = app.add_subcommand(
      "export-vdb", "Write an object's medium as an OpenVDB fog volume (docs/cli.md)");
  export_vdb->add_option("scene", exp_vdb.scene, "Scene file (JSON)")->required();
  export_vdb->add_option("-o,--output", exp_vdb.output, "Output file (.vdb)")->required();
  export_vdb
      ->add_option("--voxel-size", exp_vdb.voxel_size,
                   fmt::format("Voxel size H in world units, in [{:g}, {:g}]",
                               nimbus::kVdbExportMinVoxelSize, nimbus::kVdbExportMaxVoxelSize))
      ->required()
      ->check(voxel_size());
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
    if (settings->parsed()) return list_settings(markdown_section);
    catch_stop_signals();
    if (export_vdb->parsed()) return run_export_vdb(exp_vdb);
    if (view->parsed()) return run_view(view_args);
    return run_render(args, cluster);
  } catch (const std::bad_alloc&) {
    // Past the estimate (render/memory_estimate.h), e.g. a --max-memory above what the machine
    // has (issue 29: "nimbus: std::bad_alloc").
    end_bar_line();
    std::fprintf(stderr,
                 "nimbus: out of memory: the machine could not give what the run needed "
                 "(does --max-memory allow more than it has?)\n");
    if (cluster.size > 1) cluster_abort(kExitFailure);
    return kExitFailure;
  } catch (const std::exception& e) {
    end_bar_line();  // an error from the render thread may come while its bar is drawn
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
