#pragma once
// Writing files so that readers only ever see the old file or the complete new one: the content
// goes to a temporary file in the target's directory (rename is only atomic within one file
// system), which is then renamed over the target.
//
// Several outputs of one run are written as one transaction (OutputTransaction): every file is
// written to its temporary first, and only when all are complete are they renamed into place, so
// a run that fails or is killed while writing never leaves a new image next to an old one.
// Temporary files are registered so that a signal handler can remove them
// (remove_temporary_files_now), and the temporaries of a run that was killed outright (SIGKILL)
// are removed by the next run that writes the same output.

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace nimbus {

// The most bytes that the name of a temporary file adds to its target's: ".tmp-PID-N".
inline constexpr size_t kTempSuffixMaxBytes = 24;

// Creates a fresh temporary file next to `path`, calls `write_to(temp_path)` to fill it, flushes
// it to disk and renames it to `path` (inside an OutputTransaction: at its commit). On any
// failure, including an exception from `write_to`, the temporary file is removed and
// std::runtime_error("PATH: problem") is thrown.
void write_atomically(const std::string& path,
                      const std::function<void(const std::string& temp_path)>& write_to);

// While one is alive on a thread, write_atomically on that thread stages its files: they are
// renamed into place by commit(), in the order written, or removed if the transaction ends
// without a commit (an exception, an early return).
class OutputTransaction {
 public:
  OutputTransaction();
  ~OutputTransaction();
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;

  // Renames every staged file into place; throws std::runtime_error("PATH: problem") if one
  // cannot be, having removed the temporaries not yet renamed.
  void commit();

  // Used by write_atomically.
  void stage(std::string temp, std::string path);

 private:
  std::vector<std::pair<std::string, std::string>> staged_;  // (temporary, target)
  OutputTransaction* outer_;
};

// Removes every temporary file that write_atomically has created and not yet renamed or
// removed. Async-signal-safe: for signal handlers.
void remove_temporary_files_now();

}  // namespace nimbus
