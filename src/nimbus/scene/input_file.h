#pragma once
// A file that a scene description made the loader read (a VDB grid), recorded where it is read:
// the render's fingerprint holds the record (job/fingerprint.h), and a render's outputs must not
// overwrite the file (io/output.h).

#include <cstdint>
#include <string>

namespace nimbus {

struct InputFile {
  std::string pointer;  // the JSON pointer of the value that named it
  std::string path;     // the path it was read from
  uint64_t bytes = 0;   // its size when read
  uint64_t hash = 0;    // FNV-1a of its bytes when read (math/fnv.h)
};

// The record of `path` named at `pointer`: its size and hash now. A file that cannot be read is
// recorded with size and hash 0; the reader that follows says what is wrong with it.
InputFile record_input_file(const std::string& pointer, const std::string& path);

}  // namespace nimbus
