#include "stop_signals.h"

#include <atomic>
#include <csignal>

#include "nimbus/io/atomic_file.h"

namespace {

std::atomic<int> g_signal{0};
std::atomic<bool> g_writing{false};

extern "C" void on_stop_signal(int sig) {
  if (g_signal.exchange(sig) != 0 || g_writing.load()) {
    nimbus::remove_temporary_files_now();
    std::signal(sig, SIG_DFL);
    std::raise(sig);
  }
}

}  // namespace

void catch_stop_signals() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, on_stop_signal);
}

int stop_signal() {
  return g_signal.load();
}

void set_writing(bool writing) {
  g_writing = writing;
}

const char* signal_name(int sig) {
  return sig == SIGINT    ? "SIGINT"
         : sig == SIGTERM ? "SIGTERM"
         : sig == SIGHUP  ? "SIGHUP"
                          : "a signal";
}
