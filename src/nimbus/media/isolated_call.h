#pragma once
// Running a library's reader of untrusted files where its failures cannot hurt the caller: in a
// forked child process under limits on memory and time. A damaged OpenVDB file can make
// libopenvdb allocate what a length field claims (gigabytes from a 10 kB file), crash in its
// decompressor or print warnings; in the child these become an answer the caller can report in
// one line (vdb_file.cpp).

#include <cstdint>
#include <functional>
#include <string>

namespace nimbus {

struct IsolationLimits {
  std::uint64_t memory_bytes = 0;  // address space the child may add to what it inherits
  double seconds = 0;              // CPU seconds for the child, and twice that in wall time
};

struct IsolatedResult {
  enum class Status {
    Done,         // `work` returned; `bytes` is what it returned
    OutOfMemory,  // `work` threw std::bad_alloc: it needed more than the memory limit
    TimedOut,     // the child ran past its CPU or wall-clock limit and was killed
    Crashed,      // the child died of `signal`, or ended without an answer
    NotIsolated,  // no child could be made (fork failed, or oneTBB's worker threads could not
                  // be ended first: the call came from inside a parallel region or while
                  // another thread used oneTBB); nothing ran
  };
  Status status = Status::NotIsolated;
  std::string bytes;
  int signal = 0;
};

// Calls `work` in a forked child, with its standard error sent to /dev/null, and returns what it
// returned. `work` must turn its own expected failures into bytes; any other exception but
// std::bad_alloc counts as a crash. oneTBB's worker threads are ended before the fork, so `work`
// may use oneTBB; it must not take locks that other threads of this process (not oneTBB's) may
// hold.
IsolatedResult call_isolated(const std::function<std::string()>& work,
                             const IsolationLimits& limits);

}  // namespace nimbus
