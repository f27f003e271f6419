// `nimbus render SCENE ...`: the library's render job (nimbus/job/render_job.h) with its
// outputs, checkpoints, progress bars and display server, on one process or several MPI ranks.

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "command.h"
#include "nimbus/io/atomic_file.h"
#include "nimbus/io/display_server.h"
#include "nimbus/io/film_image.h"
#include "nimbus/io/output.h"
#include "nimbus/job/checkpoint.h"
#include "nimbus/job/fingerprint.h"
#include "nimbus/job/render_job.h"
#include "nimbus/render/memory_estimate.h"
#include "options.h"
#include "progress.h"
#include "rank_outcome.h"
#include "stop_signals.h"

namespace {

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
  std::string display_server;          // HOST:PORT of a tev viewer; "": none
  std::string aov;                     // AOV names, "albedo,normal"; "": the scene's film.aov
  std::optional<double> noise_target;  // overrides integrator.noise_target
  std::optional<int> noise_min_spp;    // overrides integrator.noise_min_spp
};

// The job's options from the command line's (the parts that are the job's).
nimbus::RenderJobOptions job_options(const RenderArgs& args) {
  nimbus::RenderJobOptions o;
  o.overrides = args.sets;
  // --aov overrides film.aov, after every --set, as --spp overrides integrator.spp.
  if (!args.aov.empty())
    o.overrides.push_back("film.aov=" + nlohmann::json(comma_separated(args.aov)).dump());
  if (args.noise_target)
    o.overrides.push_back(fmt::format("integrator.noise_target={}", *args.noise_target));
  if (args.noise_min_spp)
    o.overrides.push_back(fmt::format("integrator.noise_min_spp={}", *args.noise_min_spp));
  o.spp = args.spp;
  o.seed = args.seed;
  o.threads = args.threads;
  o.checkpoint = args.checkpoint;
  if (args.checkpoint_interval > 0) o.checkpoint_interval = args.checkpoint_interval;
  o.resume = args.resume;
  o.cancel = [] { return stop_signal() != 0; };
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
  set_writing(true);
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
    set_writing(false);
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitFailure;
  }
  set_writing(false);
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
  const int sig = stop_signal();
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
    // Of the samples; with a noise target, of those it is predicted to take (noise_progress).
    const NoiseRule rule = noise_rule(s);
    const double done = 100 * (rule.on() ? noise_progress(rule, r.film).fraction
                                         : double(held) / (double(s.width) * s.height * s.spp));
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
  if (show_progress) {
    // With a noise target the bar's fraction is of the samples predicted from the blocks'
    // errors (its ETA follows the noise's trend), and it shows the share of pixels done.
    auto converged = std::make_shared<std::atomic<double>>(-1.0);
    options.noise_progress = [converged](const NoiseProgress& p) { *converged = p.converged; };
    options.progress = progress_bar("render", [converged] {
      const double c = *converged;
      return c < 0 ? std::string() : fmt::format("  {:.1f}% px done", 100 * c);
    });
  }
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
    const int sig = stop_signal();
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

}  // namespace

Command render_command(CLI::App& app) {
  const auto args = std::make_shared<RenderArgs>();
  CLI::App* render = app.add_subcommand("render", "Render a scene file to EXR and/or PNG");
  render->add_option("scene", args->scene, "Scene file (JSON)")->required();
  render->add_option("-o,--output", args->outputs,
                     "Output image; repeatable; .exr (linear float) or .png (8-bit sRGB). "
                     "Default: <scene stem>.exr and .png in the current directory");
  render->add_option("--spp", args->spp, "Samples per pixel (overrides integrator.spp)")
      ->check(integer_in(1));
  render->add_option("--seed", args->seed, "Random seed (overrides integrator.seed)")
      ->check(unsigned_64());
  render->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->check(integer_in(1, 4096));
  render->add_option("--set", args->sets,
                     "Override a scene key: --set integrator.spp=16 (dotted path, JSON value); "
                     "repeatable");
  render->add_option("--stats", args->stats, "Write render statistics as JSON to this file");
  render->add_option("--max-memory", args->max_memory,
                     "Refuse renders estimated to need more memory than this (e.g. 8G, 512M; "
                     "default: the system's available memory)");
  render->add_flag("-q,--quiet", args->quiet, "Print nothing but errors");
  render->add_option("--checkpoint", args->checkpoint,
                     "Save the render's state to this file now and then, when it ends and when "
                     "a signal stops it (docs/cli.md)");
  render
      ->add_option("--checkpoint-interval", args->checkpoint_interval,
                   "Seconds between checkpoints (default 60)")
      ->check(positive_seconds());
  render
      ->add_option("--aov", args->aov,
                   "Write these layers into the EXR beside the colour, for denoisers: a "
                   "comma-separated list of albedo, normal, depth, variance (overrides film.aov; "
                   "docs/cli.md)")
      ->check(aov_names());
  render
      ->add_option("--noise-target", args->noise_target,
                   "Take samples in 8x8 blocks until each block's estimated relative error is at "
                   "most this, --spp being the most a pixel takes (overrides "
                   "integrator.noise_target; docs/noise-target.md)")
      ->check(CLI::Range(0.0, 1.0));
  render
      ->add_option("--noise-min-spp", args->noise_min_spp,
                   "With --noise-target, the samples every block takes before its first decision "
                   "(overrides integrator.noise_min_spp; default 16)")
      ->check(integer_in(2));
  render
      ->add_option("--display-server", args->display_server,
                   "Stream the render to a tev viewer at HOST:PORT as it refines (docs/cli.md)")
      ->check(display_address());
  render->add_option("--resume", args->resume,
                     "Continue the render of this checkpoint up to --spp (default: the spp it "
                     "was started with); later checkpoints go to the same file unless "
                     "--checkpoint says otherwise");
  return {render, [args](const Cluster& cluster) { return run_render(*args, cluster); },
          /*stoppable=*/true, /*several_ranks=*/true};
}
