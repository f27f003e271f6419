#pragma once
// The work of a render job, handed out unit by unit to whoever asks: the threads of this process
// or other processes (MPI ranks). A unit is a band of pixel rows and a range of sample indices;
// the job's film holds only finished units, so at any moment it is a valid state to checkpoint,
// and every pixel then holds its samples [0, n) for some n.
//
// The image is cut into lanes: bands of rows whose pixels hold the same number of samples (a
// film from a checkpoint of another band layout is cut into row runs of equal count). The next
// unit goes to the lane with the fewest samples handed out, so lanes advance together and the
// last units are short; several units of one lane may be out at once (a dense cloud covering
// few lanes still keeps every rank busy), and a result that arrives before an earlier one of
// its lane waits until the lane's film catches up, so the film's lanes grow in sample order. A
// lane's first unit is one sample; later ones are sized from its measured cost to take about
// `unit_seconds`, so a costly lane gets short units and the others long ones. Pixels are the
// same bits however units fall to threads or processes: sums are exact (render/exact_sum.h).
//
// With a noise target (render/noise_target.h) a lane is a band of whole 8 × 8 blocks, and a
// unit continues the blocks that are not done from the lane's state, which goes out with it
// (lane_state) since a block's decisions read all its samples; its result is the lane's new
// state. One unit of a lane is out at a time, and a lane is finished once its blocks are done.

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <vector>

#include "nimbus/job/film_patch.h"
#include "nimbus/render/counters.h"
#include "nimbus/render/film.h"
#include "nimbus/render/noise_target.h"

namespace nimbus {

struct WorkUnit {
  PixelRect rect;
  int s0 = 0, s1 = 0;  // sample indices [s0, s1)
  int lane = 0;
};

// The lanes of a film whose pixels are to reach more samples: bands of `band_height` rows,
// split into row runs where a band's pixels hold different counts.
std::vector<PixelRect> lanes_of(const Film& film, int band_height);

class WorkQueue {
 public:
  // Continues `start` (a fresh film, or a checkpoint's) until every pixel holds `spp` samples;
  // std::invalid_argument if a pixel already holds more. `ranks`: the processes taking units,
  // for samples_per_rank. With `noise` on, until every block is done (its cap `spp`; bands of
  // kNoiseBlock rows whatever `band_height`), std::invalid_argument for a film whose blocks are
  // not a noise target render's.
  WorkQueue(Film start, int spp, int band_height, int ranks, double unit_seconds,
            NoiseRule noise = {});

  bool noise_target() const { return noise_.on(); }
  // With a noise target, the unit's lane as the film holds it, which its render continues.
  FilmPatch lane_state(const WorkUnit& unit) const;

  // The next unit, or none when every sample is handed out, or after stop().
  std::optional<WorkUnit> try_next();
  // Waits for the next unit; none once the job is finished or stopped.
  std::optional<WorkUnit> wait_next();
  // Merges a unit's result (rendered by `rank` in `seconds`); with a noise target the result is
  // the lane's new state, which replaces it.
  void complete(int rank, const WorkUnit& unit, const FilmPatch& result, double seconds,
                const Counters& counters);
  // Gives a unit back unrendered (its render was cancelled).
  void abandon(const WorkUnit& unit);
  void stop();

  bool finished() const;  // every pixel holds spp samples (with a noise target, is done)
  bool stopped() const;
  bool none_out() const;         // no unit handed out and not yet completed or abandoned
  double fraction_done() const;  // of the samples this job adds (without a noise target)
  // With a noise target, the film's progress towards it (render/noise_target.h).
  NoiseProgress noise_progress() const;
  // Calls f with the job's film, the units out blocked meanwhile (to save a checkpoint).
  void with_film(const std::function<void(const Film&)>& f) const;
  Film film() const;
  Counters counters() const;
  std::vector<uint64_t> samples_per_rank() const;  // pixel samples each rank rendered

 private:
  struct Result {
    int s1 = 0;
    FilmPatch patch;
  };
  struct Lane {
    PixelRect rect;
    int done = 0;    // samples every pixel of the lane holds in the film: [0, done)
    int issued = 0;  // samples handed out: [done, issued) are out, given back or waiting
    std::vector<std::pair<int, int>> given_back;  // sample ranges to hand out again
    std::map<int, Result> waiting;                // results ahead of `done`, by their s0
    int last_chunk = 0;
    double seconds_per_sample = 0;  // of the whole lane, measured; 0: not yet
    bool out = false;               // with a noise target: a unit of the lane is out
  };
  std::optional<WorkUnit> next_locked();
  bool finished_locked() const;
  // With a noise target: the lanes of film_, and whether lane's blocks are all done.
  void make_block_lanes();
  bool lane_done(const Lane& lane) const;

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  Film film_;
  int spp_;
  NoiseRule noise_;
  double unit_seconds_;
  std::vector<Lane> lanes_;
  int out_ = 0;
  bool stopped_ = false;
  double total_ = 0, done_ = 0;  // pixel samples to add, added
  Counters counters_;
  std::vector<uint64_t> per_rank_;
};

}  // namespace nimbus
