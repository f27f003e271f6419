#pragma once
// A render's work units (job/work_queue.h) shared by the threads of this process and by the
// other processes of a job (job/job_channel.h): what a RenderJob runs with checkpoints or on
// several processes. The lead (rank 0) holds the film, hands out units on request, renders units
// itself on a thread of its own, reports the progress and saves the checkpoints; the other
// processes render the units they are given and send back the pixels.

#include <functional>
#include <vector>

#include "nimbus/job/job_channel.h"
#include "nimbus/render/counters.h"
#include "nimbus/render/film.h"
#include "nimbus/render/noise_target.h"
#include "nimbus/render/scene.h"

namespace nimbus {

struct SharedRenderSettings {
  int spp = 0;                // every pixel is to hold this many samples
  int threads = 0;            // per process; 0: all cores
  Film start;                 // the film to continue (fresh, or a checkpoint's)
  double unit_seconds = 0.5;  // aim of a unit's render time
  // Called on the lead every `checkpoint_interval` seconds and when the job stops, with the film
  // (which holds only complete units); none: no checkpoints.
  std::function<void(const Film&)> checkpoint;
  double checkpoint_interval = 60;
  // Called on the lead every `display_interval` seconds and at the end, with the film (complete
  // units only), to show the render as it refines (io/display_server.h); none: not shown.
  std::function<void(const Film&)> display;
  double display_interval = 0.25;
  std::function<void(double)> progress;  // fraction of the job done, on the lead
  // With a noise target, the film's progress towards it, on the lead, with `progress`.
  std::function<void(const NoiseProgress&)> noise_progress;
  std::function<bool()> stop;  // polled; true: stop handing out and rendering units
};

struct SharedRenderResult {
  Film film;
  Counters counters;
  double seconds = 0;
  std::vector<uint64_t> samples_per_rank;  // pixel samples rendered by each process
  bool stopped = false;                    // by `stop`, before every pixel reached spp
};

// The lead's part; `channel` null: this process alone. An exception on its render thread or its
// serving thread (a callback's, WorkQueue's) stops the other and is rethrown here.
SharedRenderResult lead_shared_render(const Scene& scene, JobChannel* channel,
                                      SharedRenderSettings settings);
// Every other process's part: renders units until the lead says the job is over.
void work_on_shared_render(const Scene& scene, JobChannel& channel, int threads,
                           const std::function<bool()>& stop);

}  // namespace nimbus
