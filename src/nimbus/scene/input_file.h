#pragma once
// Files that a scene description names (VDB grids) are read when the scene is compiled, not when
// it is loaded: a description is plain data. The description holds how to read one (a Deferred
// maker with the parameters the loader checked, and where to blame its problems); compile_scene
// runs it and records the file where it is read. The render's fingerprint holds the record
// (job/fingerprint.h), and a render's outputs must not overwrite the files (io/output.h).

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "nimbus/media/vdb_density.h"

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

// A value made when the scene is compiled, which records in `inputs` the files it reads.
template <class T>
using Deferred = std::function<T(std::vector<InputFile>& inputs)>;

// A grid file named in the description: its reader's parameters, the JSON pointer of its "file"
// key, and "SOURCE: POINTER" of the keys its problems are blamed on (JsonValue::blame): "file",
// "grid" ("" when the default name was used) and the object holding them.
struct GridInput {
  VdbParams params;
  std::string file_pointer;
  std::string file_blame, grid_blame, object_blame;

  // Records the file and calls make(params); a VdbError becomes one SceneError line at the key
  // at fault (a problem of the grid at "grid", or at the object when the default was used).
  template <class Make>
  auto read(std::vector<InputFile>& inputs, Make&& make) const {
    inputs.push_back(record_input_file(file_pointer, params.file));
    try {
      return make(params);
    } catch (const VdbError& e) {
      fail(e);
    }
  }
  [[noreturn]] void fail(const VdbError& e) const;
};

}  // namespace nimbus
