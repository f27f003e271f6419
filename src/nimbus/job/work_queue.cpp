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

WorkQueue::WorkQueue(Film start, int spp, int band_height, int ranks, double unit_seconds,
                     NoiseRule noise)
    : film_(std::move(start)),
      spp_(spp),
      noise_(noise),
      unit_seconds_(unit_seconds),
      per_rank_(ranks, 0) {
  if (noise_.on()) {
    noise_.cap = spp;
    make_block_lanes();
    return;
  }
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

void WorkQueue::make_block_lanes() {
  const int W = film_.width;
  for (int y0 = 0; y0 < film_.height; y0 += kNoiseBlock) {
    Lane lane;
    lane.rect = {0, y0, W, std::min(film_.height, y0 + kNoiseBlock)};
    // The blocks not done hold one count, the lane's; none: the lane is finished.
    int held = -1;
    for (int bx = 0; bx * kNoiseBlock < W; ++bx) {
      const NoiseBlock b = noise_block(film_, bx, y0 / kNoiseBlock);
      for (int y = b.y0; y < b.y1; ++y)
        for (int x = b.x0; x < b.x1; ++x)
          if (film_.samples[size_t(y) * W + x] != film_.samples[size_t(b.y0) * W + b.x0])
            throw std::invalid_argument(fmt::format(
                "the pixels of the block at ({}, {}) hold different counts: not a film of a render "
                "to a noise target",
                b.x0, b.y0));
      const int n = int(film_.samples[size_t(b.y0) * W + b.x0]);
      if (n > spp_)
        throw std::invalid_argument(fmt::format(
            "pixel ({}, {}) already holds {} samples, more than {}", b.x0, b.y0, n, spp_));
      if (block_done(noise_, film_, b)) continue;
      if (held >= 0 && n != held)
        throw std::invalid_argument(fmt::format(
            "blocks of rows [{}, {}) that are not done hold {} and {} samples: not a film of a "
            "render to a noise target",
            lane.rect.y0, lane.rect.y1, held, n));
      held = n;
    }
    lane.done = lane.issued = held >= 0 ? held : spp_;
    lanes_.push_back(std::move(lane));
  }
}

bool WorkQueue::lane_done(const Lane& lane) const {
  if (lane.done >= spp_) return true;
  for (int bx = 0; bx * kNoiseBlock < film_.width; ++bx)
    if (!block_done(noise_, film_, noise_block(film_, bx, lane.rect.y0 / kNoiseBlock)))
      return false;
  return true;
}

FilmPatch WorkQueue::lane_state(const WorkUnit& unit) const {
  std::lock_guard lock(mutex_);
  return copy_patch(film_, lanes_.at(unit.lane).rect);
}

std::optional<WorkUnit> WorkQueue::next_locked() {
  if (stopped_) return std::nullopt;
  Lane* best = nullptr;
  for (Lane& l : lanes_) {
    if (l.out) continue;
    if (!l.given_back.empty()) {
      const auto [s0, s1] = l.given_back.back();
      l.given_back.pop_back();
      ++out_;
      l.out = noise_.on();
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
  best->out = noise_.on();
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
    if (stopped_ || finished_locked()) return std::nullopt;
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
  double added = double(lane.rect.pixels()) * (unit.s1 - unit.s0);
  if (noise_.on()) {
    // The lane's new state replaces its old one; it adds what its blocks took.
    if (unit.s0 != lane.done) throw std::invalid_argument("a result for a unit that is not out");
    const FilmPatch before = take_patch(film_, lane.rect);
    merge_patch(film_, result);
    added = 0;
    for (size_t k = 0; k < result.samples.size(); ++k)
      added += double(result.samples[k]) - double(before.samples[k]);
    lane.done = unit.s1;
    lane.out = false;
    if (lane_done(lane)) lane.done = lane.issued = spp_;
  } else {
    lane.waiting[unit.s0] = {unit.s1, result};
    for (auto next = lane.waiting.find(lane.done); next != lane.waiting.end();
         next = lane.waiting.find(lane.done)) {
      merge_patch(film_, next->second.patch);
      lane.done = next->second.s1;
      lane.waiting.erase(next);
    }
  }
  lane.seconds_per_sample = seconds / (unit.s1 - unit.s0);
  --out_;
  done_ += added;
  per_rank_.at(rank) += uint64_t(added);
  counters_ += counters;
  changed_.notify_all();
}

void WorkQueue::abandon(const WorkUnit& unit) {
  std::lock_guard lock(mutex_);
  lanes_.at(unit.lane).given_back.emplace_back(unit.s0, unit.s1);
  lanes_.at(unit.lane).out = false;
  if (out_ > 0) --out_;
  changed_.notify_all();
}

void WorkQueue::stop() {
  std::lock_guard lock(mutex_);
  stopped_ = true;
  changed_.notify_all();
}

bool WorkQueue::finished_locked() const {
  if (out_ != 0) return false;
  if (!noise_.on()) return done_ >= total_;
  return std::all_of(lanes_.begin(), lanes_.end(), [&](const Lane& l) { return l.done >= spp_; });
}

bool WorkQueue::finished() const {
  std::lock_guard lock(mutex_);
  return finished_locked();
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

NoiseProgress WorkQueue::noise_progress() const {
  std::lock_guard lock(mutex_);
  return nimbus::noise_progress(noise_, film_);
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
