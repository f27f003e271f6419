// The cluster over MPI (OpenMPI on Debian: libopenmpi-dev).

#include <mpi.h>

#include <chrono>
#include <cstdlib>
#include <thread>

#include "cluster.h"

namespace {

bool g_started = false;

// Set by OpenMPI's mpirun (OMPI_*), by PMIx launchers, and by MPICH's Hydra (PMI_*).
bool launched_by_mpirun() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
    if (std::getenv(v)) return true;
  return false;
}

// Between polls of a waiting rank: short next to a work unit (about a second), long enough
// that the wait costs no measurable CPU time.
constexpr auto kPollInterval = std::chrono::microseconds(200);

}  // namespace

Cluster cluster_start(int* argc, char*** argv) {
  if (!launched_by_mpirun()) return {};
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
  g_started = true;
  Cluster c;
  c.mpi = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &c.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &c.size);
  return c;
}

void cluster_end() {
  if (g_started) MPI_Finalize();
  g_started = false;
}

void cluster_abort(int code) {
  if (g_started) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

// A large message waits for the receiver to post its receive: MPI_Send would spin meanwhile, on
// a worker whose pixels wait for rank 0's next poll, so the wait sleeps instead.
void cluster_send(int to, int tag, std::span<const std::byte> bytes) {
  MPI_Request request;
  MPI_Isend(bytes.data(), int(bytes.size()), MPI_BYTE, to, tag, MPI_COMM_WORLD, &request);
  for (;;) {
    int done = 0;
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) return;
    std::this_thread::sleep_for(kPollInterval);
  }
}

namespace {

ClusterMessage receive_probed(const MPI_Status& status, int tag) {
  int count = 0;
  MPI_Get_count(&status, MPI_BYTE, &count);
  ClusterMessage m;
  m.from = status.MPI_SOURCE;
  m.bytes.resize(size_t(count));
  MPI_Recv(m.bytes.data(), count, MPI_BYTE, m.from, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return m;
}

}  // namespace

std::optional<ClusterMessage> cluster_poll(int tag) {
  if (!g_started) return std::nullopt;
  int arrived = 0;
  MPI_Status status;
  MPI_Iprobe(MPI_ANY_SOURCE, tag, MPI_COMM_WORLD, &arrived, &status);
  if (!arrived) return std::nullopt;
  return receive_probed(status, tag);
}

ClusterMessage cluster_receive(int from, int tag) {
  for (;;) {
    int arrived = 0;
    MPI_Status status;
    MPI_Iprobe(from, tag, MPI_COMM_WORLD, &arrived, &status);
    if (arrived) return receive_probed(status, tag);
    std::this_thread::sleep_for(kPollInterval);
  }
}

ClusterFailure cluster_agree(int code, const std::string& message) {
  if (!g_started) return {code, 0, message};
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  int mine = code != 0 ? rank : size, first = size;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first == size) return {};
  ClusterFailure f;
  f.rank = first;
  f.code = code;
  MPI_Bcast(&f.code, 1, MPI_INT, first, MPI_COMM_WORLD);
  if (first == 0) {
    if (rank == 0) f.message = message;
  } else if (rank == first) {
    MPI_Send(message.data(), int(message.size()), MPI_CHAR, 0, 0, MPI_COMM_WORLD);
  } else if (rank == 0) {
    MPI_Status status;
    MPI_Probe(first, 0, MPI_COMM_WORLD, &status);
    int count = 0;
    MPI_Get_count(&status, MPI_CHAR, &count);
    f.message.resize(size_t(count));
    MPI_Recv(f.message.data(), count, MPI_CHAR, first, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  }
  return f;
}

uint64_t cluster_broadcast(uint64_t value) {
  if (!g_started) return value;
  MPI_Bcast(&value, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  return value;
}
