#include "nimbus/job/work_queue.h"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace nimbus {

std::vector<PixelRect> lanes_of(const Film& film, int band_height) {
  const int W = film.width, H = film.height;
  std::vector<PixelRect> lanes;
  for (int y0 = 0; y0 < H; y0 += band_height) {
    const int y1 = std::min(H, y0 + band_height);
    const uint32_t first = film.samples[size_t(y0) * W];
    bool uniform = true;
    for (int y = y0; y < y1 && uniform; ++y)
      for (int x = 0; x < W && uniform; ++x) uniform = film.samples[size_t(y) * W + x] == first;
    if (uniform) {
      lanes.push_back({0, y0, W, y1});
      continue;
    }
    for (int y = y0; y < y1; ++y)
      for (int x0 = 0; x0 < W;) {
        const uint32_t n = film.samples[size_t(y) * W + x0];
        int x1 = x0 + 1;
        while (x1 < W && film.samples[size_t(y) * W + x1] == n) ++x1;
        lanes.push_back({x0, y, x1, y + 1});
        x0 = x1;
      }
  }
  return lanes;
}

WorkQueue::WorkQueue(Film start, int spp, int band_height, int ranks, double unit_seconds)
    : film_(std::move(start)), spp_(spp), unit_seconds_(unit_seconds), per_rank_(ranks, 0) {
  for (const PixelRect& r : lanes_of(film_, band_height)) {
    const uint32_t held = film_.samples[size_t(r.y0) * film_.width + r.x0];
    if (held > uint32_t(spp))
      throw std::invalid_argument(fmt::format(
          "pixel ({}, {}) already holds {} samples, more than {}", r.x0, r.y0, held, spp));
    Lane lane;
    lane.rect = r;
    lane.done = lane.issued = int(held);
    lanes_.push_back(std::move(lane));
    total_ += double(r.pixels()) * (spp - int(held));
  }
}

std::optional<WorkUnit> WorkQueue::next_locked() {
  if (stopped_) return std::nullopt;
  Lane* best = nullptr;
  for (Lane& l : lanes_) {
    if (!l.given_back.empty()) {
      const auto [s0, s1] = l.given_back.back();
      l.given_back.pop_back();
      ++out_;
      return WorkUnit{l.rect, s0, s1, int(&l - lanes_.data())};
    }
    if (l.issued < spp_ && (!best || l.issued < best->issued)) best = &l;
  }
  if (!best) return std::nullopt;
  int chunk = 1;
  if (best->seconds_per_sample > 0)
    chunk = std::clamp(int(unit_seconds_ / best->seconds_per_sample), 1,
                       std::max(1, 4 * best->last_chunk));
  chunk = std::min(chunk, spp_ - best->issued);
  best->last_chunk = chunk;
  best->issued += chunk;
  ++out_;
  return WorkUnit{best->rect, best->issued - chunk, best->issued, int(best - lanes_.data())};
}

std::optional<WorkUnit> WorkQueue::try_next() {
  std::lock_guard lock(mutex_);
  return next_locked();
}

std::optional<WorkUnit> WorkQueue::wait_next() {
  std::unique_lock lock(mutex_);
  for (;;) {
    if (auto unit = next_locked()) return unit;
    if (stopped_ || (out_ == 0 && done_ >= total_)) return std::nullopt;
    changed_.wait(lock);
  }
}

void WorkQueue::complete(int rank, const WorkUnit& unit, const FilmPatch& result, double seconds,
                         const Counters& counters) {
  std::lock_guard lock(mutex_);
  Lane& lane = lanes_.at(unit.lane);
  if (out_ == 0 || unit.s0 < lane.done || unit.s1 > lane.issued || unit.s0 >= unit.s1 ||
      lane.waiting.contains(unit.s0) || result.rect.x0 != lane.rect.x0 ||
      result.rect.y0 != lane.rect.y0 || result.rect.x1 != lane.rect.x1 ||
      result.rect.y1 != lane.rect.y1)
    throw std::invalid_argument("a result for a unit that is not out");
  lane.waiting[unit.s0] = {unit.s1, result};
  for (auto next = lane.waiting.find(lane.done); next != lane.waiting.end();
       next = lane.waiting.find(lane.done)) {
    merge_patch(film_, next->second.patch);
    lane.done = next->second.s1;
    lane.waiting.erase(next);
  }
  lane.seconds_per_sample = seconds / (unit.s1 - unit.s0);
  --out_;
  const double added = double(lane.rect.pixels()) * (unit.s1 - unit.s0);
  done_ += added;
  per_rank_.at(rank) += uint64_t(added);
  counters_ += counters;
  changed_.notify_all();
}

void WorkQueue::abandon(const WorkUnit& unit) {
  std::lock_guard lock(mutex_);
  lanes_.at(unit.lane).given_back.emplace_back(unit.s0, unit.s1);
  if (out_ > 0) --out_;
  changed_.notify_all();
}

void WorkQueue::stop() {
  std::lock_guard lock(mutex_);
  stopped_ = true;
  changed_.notify_all();
}

bool WorkQueue::finished() const {
  std::lock_guard lock(mutex_);
  return out_ == 0 && done_ >= total_;
}

bool WorkQueue::stopped() const {
  std::lock_guard lock(mutex_);
  return stopped_;
}

bool WorkQueue::none_out() const {
  std::lock_guard lock(mutex_);
  return out_ == 0;
}

double WorkQueue::fraction_done() const {
  std::lock_guard lock(mutex_);
  return total_ > 0 ? done_ / total_ : 1.0;
}

void WorkQueue::with_film(const std::function<void(const Film&)>& f) const {
  std::lock_guard lock(mutex_);
  f(film_);
}

Film WorkQueue::film() const {
  std::lock_guard lock(mutex_);
  return film_;
}

Counters WorkQueue::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

std::vector<uint64_t> WorkQueue::samples_per_rank() const {
  std::lock_guard lock(mutex_);
  return per_rank_;
}

}  // namespace nimbus
