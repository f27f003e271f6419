// A reader run in a child process under limits (media/isolated_call.h): its answer comes back
// whole, and each way it can fail (memory, CPU time, blocking, a crash, a stray exception) comes
// back as a status instead of taking the test process with it.

#include "nimbus/media/isolated_call.h"

#include <gtest/gtest.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <new>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "support/sanitizer.h"

namespace nimbus {
namespace isolated_call_test {

using Status = IsolatedResult::Status;

const IsolationLimits kLimits{256u << 20, 1.0};

TEST(IsolatedCall, ReturnsWhatTheWorkReturnsBeyondAPipeBuffer) {
  std::string expected(5u << 20, '\0');
  for (std::size_t i = 0; i < expected.size(); ++i) expected[i] = char(i * 2654435761u >> 24);
  const IsolatedResult r = call_isolated([&] { return expected; }, kLimits);
  ASSERT_EQ(r.status, Status::Done);
  EXPECT_EQ(r.bytes, expected);
}

TEST(IsolatedCall, TheChildsMemoryDoesNotReachTheCaller) {
  int touched = 0;
  const IsolatedResult r = call_isolated(
      [&] {
        touched = 1;
        return std::string("x");
      },
      kLimits);
  ASSERT_EQ(r.status, Status::Done);
  EXPECT_EQ(touched, 0);
}

TEST(IsolatedCall, AnAllocationAboveTheLimitIsOutOfMemory) {
  const IsolatedResult r = call_isolated(
      [] {
        std::vector<char> v(std::size_t(2) << 30, 1);
        return std::string(1, v[v.size() / 2]);
      },
      kLimits);
  if (test::kAddressSanitizer)
    EXPECT_EQ(r.status, Status::Crashed);  // the sanitizer's allocator stops the child
  else
    EXPECT_EQ(r.status, Status::OutOfMemory);
  EXPECT_TRUE(r.bytes.empty());
}

TEST(IsolatedCall, ABusyChildIsStoppedAtItsCpuLimit) {
  const IsolatedResult r = call_isolated(
      [] {
        volatile unsigned spins = 0;
        for (;;) spins = spins + 1;
        return std::string();
      },
      {kLimits.memory_bytes, 0.5});
  EXPECT_EQ(r.status, Status::TimedOut);
}

TEST(IsolatedCall, ABlockedChildIsStoppedAtTheWallClockLimit) {
  const IsolatedResult r = call_isolated(
      [] {
        ::pause();
        return std::string();
      },
      {kLimits.memory_bytes, 0.5});
  EXPECT_EQ(r.status, Status::TimedOut);
}

TEST(IsolatedCall, ACrashIsReportedWithItsSignal) {
  const IsolatedResult r = call_isolated([]() -> std::string { std::abort(); }, kLimits);
  EXPECT_EQ(r.status, Status::Crashed);
  EXPECT_EQ(r.signal, SIGABRT);
}

TEST(IsolatedCall, AnExceptionOtherThanBadAllocIsACrash) {
  const IsolatedResult r =
      call_isolated([]() -> std::string { throw std::runtime_error("no"); }, kLimits);
  EXPECT_EQ(r.status, Status::Crashed);
  EXPECT_EQ(r.signal, 0);
}

// The threads of process `pid`, from /proc.
int thread_count(pid_t pid) {
  int n = 0;
  for ([[maybe_unused]] const auto& entry :
       std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/task"))
    ++n;
  return n;
}

// Starts oneTBB's workers: a parallel loop that waits (up to a second) until as many threads
// as oneTBB uses have taken part. Returns how many did.
int start_tbb_workers() {
  std::mutex m;
  std::set<std::thread::id> seen;
  const std::size_t want = std::size_t(tbb::info::default_concurrency());
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  tbb::parallel_for(0, 1000, [&](int) {
    {
      const std::lock_guard<std::mutex> lock(m);
      seen.insert(std::this_thread::get_id());
      if (seen.size() >= want) return;
    }
    if (std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
  });
  return int(seen.size());
}

// A lock held by one of oneTBB's workers when fork() copies the process stays held in the child
// for ever, and OpenVDB's own code in the child runs parallel loops: so no worker may exist then.
// The child sees its parent as it is during the call. (On a machine where oneTBB runs one thread
// there are no workers to end, and the test cannot fail.)
TEST(IsolatedCall, OneTbbsWorkersAreEndedBeforeTheFork) {
  // The process's threads without oneTBB's workers (earlier tests in this process may have
  // started them): after a first call, or, in a process of its own, before any oneTBB use.
  ASSERT_EQ(call_isolated([] { return std::string(); }, kLimits).status, Status::Done);
  const int threads_without_workers = thread_count(::getpid());
  if (start_tbb_workers() > 1) {
    EXPECT_GT(thread_count(::getpid()), threads_without_workers);
  }
  const IsolatedResult r =
      call_isolated([] { return std::to_string(thread_count(::getppid())); }, kLimits);
  ASSERT_EQ(r.status, Status::Done);
  EXPECT_EQ(r.bytes, std::to_string(threads_without_workers));
  // oneTBB starts new workers for the caller's next parallel loop.
  if (start_tbb_workers() > 1) {
    EXPECT_GT(thread_count(::getpid()), threads_without_workers);
  }
}

TEST(IsolatedCall, TheWorkMayRunParallelLoops) {
  start_tbb_workers();
  const IsolatedResult r = call_isolated(
      [] {
        const long sum = tbb::parallel_reduce(
            tbb::blocked_range<long>(1, 100001), 0L,
            [](const tbb::blocked_range<long>& range, long s) {
              for (long i = range.begin(); i != range.end(); ++i) s += i;
              return s;
            },
            [](long a, long b) { return a + b; });
        return std::to_string(sum);
      },
      kLimits);
  ASSERT_EQ(r.status, Status::Done);
  EXPECT_EQ(r.bytes, "5000050000");
}

// Inside a parallel region oneTBB's workers cannot be ended, so no child is made and the work
// does not run (the VDB reader then reads in the calling process).
TEST(IsolatedCall, InsideAParallelLoopNothingIsForked) {
  std::atomic<int> ran{0};
  std::vector<Status> status(2);
  tbb::parallel_for(0, 2, [&](int i) {
    status[std::size_t(i)] = call_isolated(
                                 [&] {
                                   ++ran;
                                   return std::string("x");
                                 },
                                 kLimits)
                                 .status;
  });
  EXPECT_EQ(status[0], Status::NotIsolated);
  EXPECT_EQ(status[1], Status::NotIsolated);
  EXPECT_EQ(ran.load(), 0);
}

}  // namespace isolated_call_test
}  // namespace nimbus
