#include "progress.h"

#include <chrono>
#include <cstdio>
#include <mutex>

#include "nimbus/scene/json_reader.h"

namespace {

// Whether a bar's line is open (drawn after a \r, not yet ended): a warning ends it first.
std::mutex g_stderr_mutex;
bool g_bar_open = false;  // guarded by g_stderr_mutex

void end_bar_line_locked() {
  if (g_bar_open) std::fprintf(stderr, "\n");
  g_bar_open = false;
}

}  // namespace

void end_bar_line() {
  std::lock_guard lock(g_stderr_mutex);
  end_bar_line_locked();
}

void print_warning(const std::string& w) {
  std::lock_guard lock(g_stderr_mutex);
  end_bar_line_locked();
  std::fprintf(stderr, "nimbus: warning: %s\n", nimbus::printable_line(w).c_str());
}

void print_progress(const char* what, double fraction, double elapsed, const std::string& note) {
  std::lock_guard lock(g_stderr_mutex);
  g_bar_open = true;
  const int width = 40, filled = static_cast<int>(fraction * width);
  const double eta = fraction > 0 ? elapsed * (1 - fraction) / fraction : 0;
  std::fprintf(stderr, "\r%-8s [%s%s] %5.1f%%  %6.1fs elapsed  ETA %6.1fs%s", what,
               std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(),
               100 * fraction, elapsed, eta, note.c_str());
  std::fflush(stderr);
}

std::function<void(double)> progress_bar(const char* what, std::function<std::string()> note) {
  const auto start = std::chrono::steady_clock::now();
  return [what, start, note = std::move(note)](double f) {
    print_progress(what, f,
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                   note ? note() : std::string());
  };
}

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
