#pragma once
// The processes that render one image together: MPI ranks when nimbus was started by mpirun
// (and built with MPI: cluster_mpi.cpp), else this process alone (cluster_single.cpp). All MPI
// calls of nimbus are behind these functions, made from the main thread only.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "nimbus/job/job_channel.h"

struct Cluster {
  int rank = 0;
  int size = 1;
  bool mpi = false;  // started by mpirun
};

// Starts MPI when the environment says mpirun started this process; call once, first.
Cluster cluster_start(int* argc, char*** argv);
// Ends MPI if it was started; call once, last, on every rank.
void cluster_end();
// Ends every rank of the job at once (MPI_Abort), for failures a rank cannot report.
[[noreturn]] void cluster_abort(int code);

using ClusterMessage = nimbus::JobChannel::Message;

void cluster_send(int to, int tag, std::span<const std::byte> bytes);
// A message with `tag` from any rank, if one has arrived; never waits.
std::optional<ClusterMessage> cluster_poll(int tag);
// Waits for a message with `tag` from `from`, sleeping between polls so that a waiting rank
// costs no CPU time (MPI's own waits spin).
ClusterMessage cluster_receive(int from, int tag);

// Collective: every rank passes its own outcome (code 0: fine); all get the same answer, the
// code of the lowest rank that failed (0 if none) and, on rank 0, that rank's message.
struct ClusterFailure {
  int code = 0;
  int rank = 0;
  std::string message;
};
ClusterFailure cluster_agree(int code, const std::string& message);

// Collective: rank 0's value on every rank.
uint64_t cluster_broadcast(uint64_t value);

// The cluster as a render job's channel (nimbus/job/job_channel.h). The job's messages use tags
// 1 and 2; the command line's own, 3 and up.
class ClusterChannel : public nimbus::JobChannel {
 public:
  explicit ClusterChannel(const Cluster& cluster) : cluster_(cluster) {}
  int rank() const override { return cluster_.rank; }
  int size() const override { return cluster_.size; }
  void send(int to, int tag, std::span<const std::byte> bytes) override {
    cluster_send(to, tag, bytes);
  }
  std::optional<Message> poll(int tag) override { return cluster_poll(tag); }
  Message receive(int from, int tag) override { return cluster_receive(from, tag); }

 private:
  Cluster cluster_;
};
