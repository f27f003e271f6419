// A reader run in a child process under limits (media/isolated_call.h): its answer comes back
// whole, and each way it can fail (memory, CPU time, blocking, a crash, a stray exception) comes
// back as a status instead of taking the test process with it.

#include "nimbus/media/isolated_call.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <new>
#include <stdexcept>
#include <vector>

#include "support/sanitizer.h"

namespace nimbus {
namespace {

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

}  // namespace
}  // namespace nimbus
