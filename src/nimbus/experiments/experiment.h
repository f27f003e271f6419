#pragma once
// The paper-reproduction experiments (docs/reproduction.md), run by `nimbus experiment NAME`.
// Each writes CSV (and, for some, images) into an output directory and returns what it wrote and
// a short summary of its measured numbers.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace nimbus {

struct ExperimentOptions {
  std::filesystem::path out;     // existing directory for the results
  std::filesystem::path scenes;  // directory holding the scene files (scenes/ of the source tree)
  bool quick = false;            // a tiny variant: seconds, for tests and smoke runs
  uint64_t seed = 0;
  int threads = 0;  // 0: all hardware threads
};

struct ExperimentReport {
  std::vector<std::filesystem::path> files;  // every file written, CSV first
  std::string summary;                       // a few lines of measured numbers
};

struct Experiment {
  std::string name;
  std::string description;
  std::function<ExperimentReport(const ExperimentOptions&)> run;
};

// Every experiment, in the order of the paper's figures.
const std::vector<Experiment>& experiments();

// Writes `text` to dir/name atomically and returns the path.
std::filesystem::path write_text(const std::filesystem::path& dir, const std::string& name,
                                 const std::string& text);

// Calls body(i) for i in [0, n) on up to `threads` threads (0: all). Bodies must write disjoint
// results, so that what they compute does not depend on the thread count.
void parallel_for_index(int n, int threads, const std::function<void(int)>& body);

}  // namespace nimbus
