#pragma once
// A file that a scene description made the loader read (a VDB grid), recorded where it is read.

#include <string>

namespace nimbus {

struct InputFile {
  std::string pointer;  // the JSON pointer of the value that named it
  std::string path;     // the path it was read from
};

}  // namespace nimbus
