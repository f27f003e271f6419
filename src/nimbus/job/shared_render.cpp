#include "nimbus/job/shared_render.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <thread>
#include <type_traits>

#include "nimbus/job/film_patch.h"
#include "nimbus/job/work_queue.h"
#include "nimbus/render/noise_target.h"
#include "nimbus/render/renderer.h"

namespace nimbus {
namespace {

using Clock = std::chrono::steady_clock;

// Message tags: a worker's report (its last unit's result, if any, and a request for the next;
// or that it leaves the job) and the lead's reply (a unit, or the end of the job).
constexpr int kReportTag = 1, kReplyTag = 2;

// A worker stopped by a signal gives back the unit it was rendering and leaves the job
// (Abandoned); rank 0 finishes the job with the others, so a signal to one rank alone stops
// only that rank.
enum class Report : uint8_t { Request, Result, Abandoned };
enum class Reply : uint8_t { Unit, Done };

static_assert(std::is_trivially_copyable_v<WorkUnit> && std::is_trivially_copyable_v<Counters>);

// A message's bytes. Appended by resize and memcpy: GCC 12 warns, wrongly, about
// vector::insert of byte ranges (-Warray-bounds).
struct Writer {
  std::vector<std::byte> bytes;
  void append(const void* data, size_t size) {
    const size_t at = bytes.size();
    bytes.resize(at + size);
    if (size > 0) std::memcpy(bytes.data() + at, data, size);
  }
  template <class T>
  void put(const T& v) {
    append(&v, sizeof v);
  }
};

struct Reader {
  std::span<const std::byte> bytes;
  template <class T>
  T get() {
    if (bytes.size() < sizeof(T)) throw std::runtime_error("a message cut short");
    T v;
    std::memcpy(&v, bytes.data(), sizeof v);
    bytes = bytes.subspan(sizeof v);
    return v;
  }
};

// A unit's render into `scratch` (which holds no samples in the unit's pixels, or with a noise
// target the lane's state), cancelled when `stop` says so; the result is moved out of the
// scratch film.
struct UnitResult {
  FilmPatch patch;
  RenderStats stats;
};
UnitResult render_unit(const Scene& scene, Film& scratch, const WorkUnit& u, int threads,
                       const std::function<bool()>& stop) {
  RenderOptions options;
  options.threads = threads;
  options.range = {u.rect.x0, u.rect.y0, u.rect.x1, u.rect.y1, u.s0, u.s1};
  options.cancel = stop;
  UnitResult r;
  r.stats = render_into(scene, scratch, options);
  r.patch = take_patch(scratch, u.rect);
  return r;
}

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// Rank 0's main thread until the job is over, or until the lead's render thread `failed` (its
// unit may stay out for good: issue 44, a throw from WorkQueue::complete hung the render):
// answers the other ranks' reports, draws the progress, saves checkpoints.
void serve(WorkQueue& queue, JobChannel* channel, const SharedRenderSettings& s,
           const std::function<bool()>& stop, const std::atomic<bool>& failed) {
  const int ranks = channel ? channel->size() : 1;
  std::vector<int> waiting;  // ranks that asked for a unit and have not had an answer
  int gone = 0;              // ranks that were told the job is over, or left it
  auto last_checkpoint = Clock::now();
  auto last_progress = Clock::time_point{};
  auto last_display = Clock::time_point{};
  for (;;) {
    if (failed.load()) return;
    if (stop() && !queue.stopped()) queue.stop();
    while (std::optional<JobChannel::Message> m =
               channel ? channel->poll(kReportTag) : std::nullopt) {
      Reader in{m->bytes};
      const auto kind = in.get<Report>();
      if (kind == Report::Result || kind == Report::Abandoned) {
        const auto unit = in.get<WorkUnit>();
        const auto seconds = in.get<double>();
        const auto counters = in.get<Counters>();
        if (kind == Report::Result)
          queue.complete(m->from, unit, unpack_patch(in.bytes), seconds, counters);
        else
          queue.abandon(unit);
      }
      if (kind == Report::Request || kind == Report::Result)
        waiting.push_back(m->from);
      else
        ++gone;
    }
    const bool over = queue.stopped() || queue.finished();
    for (auto it = waiting.begin(); it != waiting.end();) {
      Writer out;
      if (const std::optional<WorkUnit> u = queue.try_next()) {
        out.put(Reply::Unit);
        out.put(*u);
        if (queue.noise_target()) {
          const std::vector<std::byte> state = pack_patch(queue.lane_state(*u));
          out.append(state.data(), state.size());
        }
      } else if (over) {
        out.put(Reply::Done);
        ++gone;
      } else {
        ++it;
        continue;
      }
      channel->send(*it, kReplyTag, out.bytes);
      it = waiting.erase(it);
    }
    // With a noise target, the share of the predicted samples, and of the pixels done
    // (render/noise_target.h): a pass over the film's blocks, so twice a second.
    if (s.progress && seconds_since(last_progress) > (queue.noise_target() ? 0.5 : 0.1)) {
      if (queue.noise_target()) {
        const NoiseProgress p = queue.noise_progress();
        if (s.noise_progress) s.noise_progress(p);
        s.progress(queue.finished() ? 1.0 : p.fraction);
      } else {
        s.progress(queue.fraction_done());
      }
      last_progress = Clock::now();
    }
    if (s.display && !over && seconds_since(last_display) >= s.display_interval) {
      queue.with_film(s.display);
      last_display = Clock::now();
    }
    if (s.checkpoint && !over && seconds_since(last_checkpoint) >= s.checkpoint_interval) {
      queue.with_film(s.checkpoint);
      last_checkpoint = Clock::now();
    }
    if (over && queue.none_out() && gone == ranks - 1) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

}  // namespace

SharedRenderResult lead_shared_render(const Scene& scene, JobChannel* channel,
                                      SharedRenderSettings s) {
  const int ranks = channel ? channel->size() : 1;
  const auto start = Clock::now();
  const int H = scene.settings.height;
  // Four bands per rank at least, so every rank has lanes to take; at most 16 rows (the
  // renderer's tile), so the bands of a dense region are short.
  const int band_height = std::clamp(H / (4 * ranks), 1, 16);
  WorkQueue queue(std::move(s.start), s.spp, band_height, ranks, s.unit_seconds,
                  noise_rule(scene.settings));
  // An exception on either thread ends the job: the other stops at its next pixel or poll, and
  // the exception leaves this function.
  std::atomic<bool> failed{false};
  const auto stop = [&] { return failed.load(std::memory_order_relaxed) || (s.stop && s.stop()); };

  std::exception_ptr local_failure;
  std::thread local([&] {
    try {
      Film scratch = make_film(scene);
      while (const std::optional<WorkUnit> u = queue.wait_next()) {
        if (queue.noise_target()) merge_patch(scratch, queue.lane_state(*u));
        const UnitResult r = render_unit(scene, scratch, *u, s.threads, stop);
        if (r.stats.cancelled)
          queue.abandon(*u);
        else
          queue.complete(0, *u, r.patch, r.stats.seconds, r.stats.counters);
      }
    } catch (...) {
      local_failure = std::current_exception();
      failed = true;
      queue.stop();
    }
  });

  try {
    serve(queue, channel, s, stop, failed);
  } catch (...) {
    failed = true;
    queue.stop();
    local.join();
    throw;
  }
  local.join();
  if (local_failure) std::rethrow_exception(local_failure);

  SharedRenderResult result;
  result.stopped = !queue.finished();
  if (s.progress && !result.stopped) s.progress(1.0);
  if (s.checkpoint) queue.with_film(s.checkpoint);
  if (s.display) queue.with_film(s.display);  // the last update: the film written
  result.film = queue.film();
  result.counters = queue.counters();
  result.samples_per_rank = queue.samples_per_rank();
  result.seconds = seconds_since(start);
  return result;
}

void work_on_shared_render(const Scene& scene, JobChannel& channel, int threads,
                           const std::function<bool()>& stop) {
  Film scratch = make_film(scene);
  Writer report;
  report.put(Report::Request);
  for (;;) {
    channel.send(0, kReportTag, report.bytes);
    const JobChannel::Message m = channel.receive(0, kReplyTag);
    Reader in{m.bytes};
    if (in.get<Reply>() == Reply::Done) return;
    const auto unit = in.get<WorkUnit>();
    // With a noise target the lane's state follows, which the unit continues (work_queue.h).
    if (!in.bytes.empty()) merge_patch(scratch, unpack_patch(in.bytes));
    const UnitResult r = render_unit(scene, scratch, unit, threads, stop);
    report = {};
    if (r.stats.cancelled) {
      report.put(Report::Abandoned);
      report.put(unit);
      report.put(r.stats.seconds);
      report.put(r.stats.counters);
      channel.send(0, kReportTag, report.bytes);
      return;
    }
    report.put(Report::Result);
    report.put(unit);
    report.put(r.stats.seconds);
    report.put(r.stats.counters);
    const std::vector<std::byte> patch = pack_patch(r.patch);
    report.append(patch.data(), patch.size());
  }
}

}  // namespace nimbus
