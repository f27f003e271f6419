#pragma once
// Writing a file so that readers only ever see the old file or the complete new one: the
// content goes to a temporary file in the target's directory (rename is only atomic within one
// file system), which is then renamed over the target.

#include <functional>
#include <string>

namespace nimbus {

// Creates a fresh temporary file next to `path`, calls `write_to(temp_path)` to fill it, flushes
// it to disk and renames it to `path`. On any failure, including an exception from `write_to`,
// the temporary file is removed and std::runtime_error("PATH: problem") is thrown.
void write_atomically(const std::string& path,
                      const std::function<void(const std::string& temp_path)>& write_to);

}  // namespace nimbus
