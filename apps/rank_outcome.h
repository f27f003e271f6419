#pragma once
// A step's outcome under mpirun, where every rank runs each step of a render and all agree on
// how it went; and the relay of the exit code from rank 0 to the others at the end.

#include <fmt/format.h>

#include <string>

#include "cluster.h"
#include "command.h"
#include "nimbus/job/render_job.h"
#include "nimbus/scene/json_reader.h"

// A step's outcome: exit code 0 (go on), or the code and the one line to print.
struct Outcome {
  int code = 0;
  std::string message;
};

// Every rank's outcomes agreed on (cluster_agree): a failure is printed once, by rank 0, and
// every rank exits with its code. Returns that code.
int agree(const Cluster& cluster, const Outcome& mine);

// A step of the render job as an outcome: its refusals are bad input (exit 2), one line.
template <class Step>
Outcome attempt(Step&& step) {
  try {
    step();
  } catch (const nimbus::SceneError& e) {
    return {kExitBadInput, e.what()};
  } catch (const nimbus::JobError& e) {
    return {kExitBadInput, fmt::format("nimbus: {}", e.what())};
  }
  return {};
}

// After the job, rank 0 tells every other rank its exit code; they wait for it.
void send_exit_code(const Cluster& cluster, int code);
int receive_exit_code();
