#include "rank_outcome.h"

#include <fmt/format.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <span>

namespace {

// The command line's own message tag (cluster.h: the job's use 1 and 2).
constexpr int kExitTag = 3;

}  // namespace

int agree(const Cluster& cluster, const Outcome& mine) {
  const ClusterFailure f = cluster_agree(mine.code, mine.message);
  if (f.code != 0 && cluster.rank == 0)
    std::fprintf(
        stderr, "%s\n",
        nimbus::printable_line(f.rank == 0 ? f.message
                                           : fmt::format("nimbus: rank {}: {}", f.rank, f.message))
            .c_str());
  return f.code;
}

void send_exit_code(const Cluster& cluster, int code) {
  const int32_t c = code;
  for (int r = 1; r < cluster.size; ++r) cluster_send(r, kExitTag, std::as_bytes(std::span(&c, 1)));
}

int receive_exit_code() {
  const ClusterMessage m = cluster_receive(0, kExitTag);
  int32_t c = kExitFailure;
  if (m.bytes.size() == sizeof c) std::memcpy(&c, m.bytes.data(), sizeof c);
  return c;
}
