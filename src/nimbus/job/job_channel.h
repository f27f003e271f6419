#pragma once
// The processes that render one image together, as a render job sees them (job/render_job.h):
// this process's rank among them, their number, and messages by tag. A program implements it
// over its transport (nimbus's command line over MPI, apps/cluster_mpi.cpp); a job in one
// process needs none. Called from one thread of each process.

#include <cstddef>
#include <optional>
#include <span>
#include <vector>

namespace nimbus {

class JobChannel {
 public:
  struct Message {
    int from = 0;
    std::vector<std::byte> bytes;
  };
  virtual ~JobChannel() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  virtual void send(int to, int tag, std::span<const std::byte> bytes) = 0;
  // A message with `tag` from any process, if one has arrived; never waits.
  virtual std::optional<Message> poll(int tag) = 0;
  // Waits for a message with `tag` from `from`.
  virtual Message receive(int from, int tag) = 0;
};

}  // namespace nimbus
