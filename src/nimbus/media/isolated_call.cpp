#include "nimbus/media/isolated_call.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <new>

namespace nimbus {
namespace {

// The process's present address-space size (VmSize), which the child inherits and its limit
// must lie above; 0 where /proc cannot tell.
std::uint64_t address_space_bytes() {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "VmSize:") {
      std::uint64_t kib = 0;
      status >> kib;
      return kib * 1024;
    }
    status.ignore(1 << 16, '\n');
  }
  return 0;
}

// Ends oneTBB's worker threads, waiting for them, so that none holds a lock when fork() copies
// the process: the child would wait for ever on a lock that a worker held at that moment, and
// its work uses oneTBB (OpenVDB's tree destructor runs a parallel_for). False where oneTBB
// cannot end them now: the caller is inside a parallel region, or another thread uses oneTBB.
// The next parallel algorithm starts new workers.
bool end_tbb_workers() {
  tbb::task_scheduler_handle handle{tbb::attach{}};
  return tbb::finalize(handle, std::nothrow);
}

void write_all(int fd, const char* bytes, std::size_t size) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, bytes + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    done += std::size_t(n);
  }
}

// The child's whole life: limits, the work, its answer on `fd`. A one-byte tag leads the
// answer: 'D' and the bytes, or 'M' for std::bad_alloc. Never returns.
[[noreturn]] void run_child(int fd, const std::function<std::string()>& work,
                            const IsolationLimits& limits, std::uint64_t inherited) {
  if (const int null = ::open("/dev/null", O_WRONLY); null >= 0) ::dup2(null, STDERR_FILENO);
  const rlimit memory{inherited + limits.memory_bytes, inherited + limits.memory_bytes};
  const auto cpu_seconds = rlim_t(std::ceil(limits.seconds));
  const rlimit cpu{cpu_seconds, cpu_seconds + 1};
  ::setrlimit(RLIMIT_AS, &memory);
  ::setrlimit(RLIMIT_CPU, &cpu);
  const rlimit no_core{0, 0};  // SIGXCPU and SIGABRT would otherwise dump the parent's image
  ::setrlimit(RLIMIT_CORE, &no_core);
  char tag = 'D';
  std::string bytes;
  try {
    bytes = work();
  } catch (const std::bad_alloc&) {
    tag = 'M';
    bytes.clear();
  } catch (...) {
    ::_exit(3);
  }
  write_all(fd, &tag, 1);
  write_all(fd, bytes.data(), bytes.size());
  // _exit: no atexit handlers or static destructors, which belong to the parent's libraries.
  ::_exit(0);
}

}  // namespace

IsolatedResult call_isolated(const std::function<std::string()>& work,
                             const IsolationLimits& limits) {
  IsolatedResult result;
  if (!end_tbb_workers()) return result;
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) return result;
  const std::uint64_t inherited = address_space_bytes();
  std::fflush(nullptr);  // what stdio holds would otherwise be written twice
  const pid_t child = ::fork();
  if (child < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return result;
  }
  if (child == 0) {
    ::close(fds[0]);
    run_child(fds[1], work, limits, inherited);
  }
  ::close(fds[1]);

  // Read the answer while the child writes it (a pipe holds 64 kB), up to a wall-clock deadline
  // that catches a child blocked rather than busy (RLIMIT_CPU catches the busy one).
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::duration<double>(2 * limits.seconds + 1);
  bool timed_out = false;
  char buffer[1 << 16];
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) {
      timed_out = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, int(std::min<long long>(left, 1 << 30)));
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) continue;
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    result.bytes.append(buffer, std::size_t(n));
  }
  ::close(fds[0]);
  if (timed_out) ::kill(child, SIGKILL);
  int wstatus = 0;
  while (::waitpid(child, &wstatus, 0) < 0 && errno == EINTR) {
  }

  const bool killed_for_time =
      WIFSIGNALED(wstatus) && (WTERMSIG(wstatus) == SIGXCPU || WTERMSIG(wstatus) == SIGKILL);
  if (timed_out || killed_for_time) {
    result.status = IsolatedResult::Status::TimedOut;
    result.bytes.clear();
  } else if (WIFEXITED(wstatus) && WEXITSTATUS(wstatus) == 0 && !result.bytes.empty()) {
    result.status =
        result.bytes[0] == 'M' ? IsolatedResult::Status::OutOfMemory : IsolatedResult::Status::Done;
    result.bytes.erase(0, 1);
  } else {
    result.status = IsolatedResult::Status::Crashed;
    result.signal = WIFSIGNALED(wstatus) ? WTERMSIG(wstatus) : 0;
    result.bytes.clear();
  }
  return result;
}

}  // namespace nimbus
