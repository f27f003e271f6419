// A cluster of one process: nimbus built without MPI.

#include <cstdlib>
#include <stdexcept>

#include "cluster.h"

Cluster cluster_start(int*, char***) {
  return {};
}

void cluster_end() {}

void cluster_abort(int code) {
  std::exit(code);
}

void cluster_send(int, int, std::span<const std::byte>) {
  throw std::logic_error("no other process to send to");
}

std::optional<ClusterMessage> cluster_poll(int) {
  return std::nullopt;
}

ClusterMessage cluster_receive(int, int) {
  throw std::logic_error("no other process to receive from");
}

ClusterFailure cluster_agree(int code, const std::string& message) {
  return {code, 0, message};
}

uint64_t cluster_broadcast(uint64_t value) {
  return value;
}
