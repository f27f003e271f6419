#pragma once
// A render as a job: what a render is beyond render_into (render/renderer.h). It loads the scene
// with its overrides, continues a checkpoint after checking that it is of this scene, refuses a
// render the machine cannot hold, compiles, renders with progress and cancellation, saves
// checkpoints on an interval and when stopped, shares the work with other processes
// (job/job_channel.h), and reports the summary and the --stats JSON. `nimbus render` is this job
// driven from the command line; a program embedding nimbus, or a binding, drives the same job.
//
//   RenderJob job(options);            // spp, seed, threads, checkpoint, resume, callbacks
//   job.prepare("scene.json");         // or set_scene(scene, identity) for a scene built in code
//   JobOutcome r = job.run();          // r.film; r.stopped if cancelled
//
// Processes of one job call the steps of prepare themselves, agreeing between them: the lead
// (rank 0) alone reads the checkpoint (read_resume) and checks (check, check_compiled); every
// process loads and compiles; the lead runs, the others work.

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "nimbus/io/output.h"
#include "nimbus/job/checkpoint.h"
#include "nimbus/job/job_channel.h"
#include "nimbus/media/build_monitor.h"
#include "nimbus/render/counters.h"
#include "nimbus/render/film.h"
#include "nimbus/render/noise_target.h"
#include "nimbus/render/scene.h"
#include "nimbus/scene/scene_desc.h"

namespace nimbus {

// A request the job refuses before rendering (a checkpoint of another scene, more memory than
// allowed): one line, the command line's exit 2. Problems of the scene file are SceneError.
struct JobError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct RenderJobOptions {
  std::vector<std::string> overrides;  // scene keys set as KEY=VALUE (--set), in order
  int spp = 0;                      // > 0: overrides integrator.spp; 0: the scene's, or resuming,
                                    // the spp the checkpoint's render was asked for
  std::optional<uint64_t> seed;     // overrides integrator.seed
  int threads = 0;                  // per process; 0: all cores
  std::string checkpoint;           // where the job's state is saved; "": none, or resuming, there
  double checkpoint_interval = 60;  // seconds between checkpoints
  std::string resume;               // a checkpoint to continue
  std::optional<uint64_t> max_memory;    // bytes; none: the memory the system has available
  std::function<void(double)> progress;  // the fraction done, now and then
  std::function<bool()> cancel;          // polled; true stops the job
  std::function<void(const std::string&)> warning;  // a problem the job survives, one line
  // Called a few times a second with the film so far, on the lead: --display-server
  // (io/display_server.h). Set, the job renders in passes of samples over the whole film (in
  // units with checkpoints or processes); the caller shows the outcome's film at the end.
  std::function<void(const Film&)> display;
  // With a noise target, called now and then with the share of pixels done and of the samples
  // predicted (render/noise_target.h).
  std::function<void(const NoiseProgress&)> noise_progress;
};

struct JobOutcome {
  // Every pixel at spp (with a noise target, each block done), or stopped: the samples done
  // (whole units with checkpoints).
  Film film;
  Counters counters;
  double seconds = 0;
  int threads = 0;  // per process
  int processes = 1;
  std::vector<uint64_t> samples_per_rank;  // several processes: pixel samples each rendered
  uint64_t samples_at_start = 0;           // in the resumed film
  bool stopped = false;                    // cancelled before every pixel reached spp
  // Why the last checkpoint due could not be saved; "": saved, or none was due.
  std::string checkpoint_failure;
};

class RenderJob {
 public:
  explicit RenderJob(RenderJobOptions options);

  // read_resume, load, check, compile and check_compiled, for a job in one process.
  void prepare(const std::string& scene_file, const BuildMonitor& monitor = {});
  // A scene built in code (compiled, finish_scene called) instead of a file: `identity`, any
  // JSON that changes when the scene does, stands for the scene in checkpoints. Checks as check.
  void set_scene(Scene scene, const nlohmann::json& identity);

  // The lead's: reads the checkpoint to continue, if any, and returns the spp to render to
  // (0: the scene's), which every process must load with. JobError for a bad checkpoint.
  int read_resume();
  // Loads the scene file with the overrides, `spp` (if > 0) and the seed. SceneError.
  void load(const std::string& scene_file, int spp);
  // As load, for a scene document in memory (a program's, or Python's nimbus.load_dict):
  // `source` names it in messages; relative file names resolve against the current directory.
  void load_document(const nlohmann::json& document, const std::string& source, int spp);
  // The lead's: the memory suffices, and the checkpoint to continue is of this scene's document
  // and settings, with its film size and no pixel past its spp. JobError.
  void check() const;
  // Compiles the scene (reads its files and records them, builds the majorant octrees); false if
  // the monitor cancelled it. SceneError.
  bool compile(const BuildMonitor& monitor = {});
  // The lead's, once compiled: the checkpoint to continue read the same files, and built the
  // same majorant octrees. JobError.
  void check_compiled() const;

  // The lead's (rank 0 of `channel`, or the only process): renders to spp.
  JobOutcome run(JobChannel* channel = nullptr);
  // Every other process's: renders the units the lead hands out until the job is over.
  void work(JobChannel& channel);

  // What --stats writes for an outcome (render/stats.h, with the processes and the checkpoint).
  nlohmann::json stats(const JobOutcome& outcome) const;
  // "64x48, 16 spp in 0.52 s (9.1e+04 samples/s, 2 threads)", with the processes if several.
  std::string summary(const JobOutcome& outcome) const;

  // The files the job reads (the scene file, those compiling it read, the checkpoint it
  // continues) and writes (checkpoints), for io/output.h's check_outputs_distinct.
  std::vector<NamedFile> files_read() const;
  std::vector<NamedFile> files_written() const;

  const SceneDesc& description() const { return desc_; }
  const Scene& scene() const { return scene_; }
  const RenderJobOptions& options() const { return options_; }
  // Where checkpoints are saved: --checkpoint, or else the file resumed; "": none.
  const std::string& checkpoint_file() const { return checkpoint_file_; }

 private:
  JobOutcome run_at_once();
  JobOutcome run_in_passes();
  JobOutcome run_shared(JobChannel* channel);

  RenderJobOptions options_;
  std::string checkpoint_file_;
  // The options' overrides and seed, as --set overrides of the document.
  std::vector<std::string> overrides() const;
  // desc as the job's description, to render at spp (> 0; else its own).
  void use_description(SceneDesc desc, int spp);

  std::string scene_file_;
  std::optional<Checkpoint> resumed_;
  SceneDesc desc_;
  std::vector<InputFile> inputs_;  // the files compiling the description read
  Scene scene_;
  nlohmann::json fingerprint_;
  bool compiled_ = false;
};

// Memory the job's render needs, against `max_memory` (or the available memory when none):
// JobError with the estimate's parts when it does not fit. `octrees` as Scene's rule
// (solid_octree_count).
void check_render_memory(const SceneDesc& desc, int threads, std::optional<uint64_t> max_memory);

// What the description's objects take once compiled, every instance counted (object_memory in
// render/memory_estimate.h).
double object_memory(const SceneDesc& desc);

}  // namespace nimbus
