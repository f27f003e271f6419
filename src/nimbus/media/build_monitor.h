#pragma once
// Watching a build that may take seconds (majorant octrees, VDB exports) from its parallel
// workers: a progress callback and a cancel poll, and the watch that workers report through.

#include <atomic>
#include <functional>
#include <mutex>

namespace nimbus {

// Both are optional; progress is called from one thread at a time with the fraction done,
// ending with 1 for a build that finishes. Once cancel returns true the build stops early and
// what it returns must not be used.
struct BuildMonitor {
  std::function<void(double)> progress;
  std::function<bool()> cancel;
  // compile_scene's objects, before the octrees (10^6 instances take seconds): their own
  // progress, called as progress is.
  std::function<void(double)> objects;
};

// Reports a build's progress from parallel workers: whichever thread gets the lock reports, the
// others go on. Fractions that arrive out of order (a slower thread) are dropped, so the reports
// rise, and steps below 0.1 % are not worth a report. Cancellation is polled the same way and
// remembered.
class BuildWatch {
 public:
  explicit BuildWatch(const BuildMonitor& m) : m_(m) {}
  void report(double fraction) {
    if (!m_.progress) return;
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || (fraction < 1 && fraction < last_ + 1e-3)) return;
    last_ = fraction;
    m_.progress(fraction);
  }
  bool cancelled() {
    if (!cancelled_.load(std::memory_order_relaxed) && m_.cancel && m_.cancel())
      cancelled_.store(true, std::memory_order_relaxed);
    return cancelled_.load(std::memory_order_relaxed);
  }

 private:
  const BuildMonitor& m_;
  std::mutex mutex_;
  double last_ = -1;
  std::atomic<bool> cancelled_{false};
};

}  // namespace nimbus
