#include "nimbus/scene/input_file.h"

#include <fmt/format.h>

#include <vector>

#include "nimbus/math/fnv.h"
#include "nimbus/os/regular_file.h"
#include "nimbus/scene/json_reader.h"

namespace nimbus {

InputFile record_input_file(const std::string& pointer, const std::string& path) {
  InputFile f{pointer, path};
  try {
    RegularFile file(path);
    uint64_t h = kFnvOffset, bytes = 0;
    std::vector<char> buffer(1 << 16);
    std::istream& in = file.stream();
    while (in.read(buffer.data(), std::streamsize(buffer.size())) || in.gcount() > 0) {
      const auto n = size_t(in.gcount());
      h = hash_bytes(std::as_bytes(std::span(buffer.data(), n)), h);
      bytes += n;
    }
    f.bytes = bytes;
    f.hash = h;
  } catch (const FileOpenError&) {
    // Not a regular file (a FIFO, /dev/zero never ends): recorded as unreadable; its reader says
    // why.
  }
  return f;
}

void GridInput::fail(const VdbError& e) const {
  const std::string& at = e.key != "grid"       ? file_blame
                          : !grid_blame.empty() ? grid_blame
                                                : object_blame;
  throw SceneError(fmt::format("{}: {}", at, e.what()));
}

}  // namespace nimbus
