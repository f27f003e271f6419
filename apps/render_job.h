#pragma once
// A render as a job of work units (nimbus/job/work_queue.h) shared by the threads of this
// process and by the other ranks of a cluster (cluster.h): what `nimbus render` runs under
// mpirun and with --checkpoint or --resume. Rank 0 leads: it holds the film, hands out units on
// request, renders units itself on a thread of its own, draws the progress and saves the
// checkpoints; the other ranks render the units they are given and send back the pixels.

#include <functional>
#include <string>
#include <vector>

#include "cluster.h"
#include "nimbus/render/counters.h"
#include "nimbus/render/film.h"
#include "nimbus/render/scene.h"

struct JobSettings {
  int spp = 0;                // every pixel is to hold this many samples
  int threads = 0;            // per rank; 0: all cores
  nimbus::Film start;         // the film to continue (fresh, or a checkpoint's)
  double unit_seconds = 0.5;  // aim of a unit's render time
  // Called on rank 0 every `checkpoint_interval` seconds and when the job stops, with the film
  // (which holds only complete units); none: no checkpoints.
  std::function<void(const nimbus::Film&)> checkpoint;
  double checkpoint_interval = 60;
  std::function<void(double)> progress;  // fraction of the job done, on rank 0
  std::function<bool()> stop;            // polled; true: stop handing out and rendering units
};

struct JobResult {
  nimbus::Film film;
  nimbus::Counters counters;
  double seconds = 0;
  std::vector<uint64_t> samples_per_rank;  // pixel samples rendered by each rank
  bool stopped = false;                    // by `stop`, before every pixel reached spp
};

// Rank 0's part.
JobResult lead_job(const nimbus::Scene& scene, const Cluster& cluster, JobSettings settings);
// Every other rank's part: renders units until rank 0 says the job is over.
void work_on_job(const nimbus::Scene& scene, int threads, const std::function<bool()>& stop);

// After the job, rank 0 tells every other rank its exit code; they wait for it.
void send_exit_code(const Cluster& cluster, int code);
int receive_exit_code();
