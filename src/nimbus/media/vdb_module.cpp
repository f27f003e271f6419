#include "nimbus/media/vdb_module.h"

#include <algorithm>
#include <string>
#include <vector>

#include "nimbus/os/shared_module.h"

// The folders to look in, separated by ':', relative ones from the folder of the binary that
// holds this code (CMakeLists.txt: the build tree's executables and Python module, an installed
// bin/ and Python package, then the install's libdir).
#ifndef NIMBUS_MODULE_DIRS
#define NIMBUS_MODULE_DIRS "."
#endif

namespace nimbus {
namespace {

std::vector<std::string> module_folders() {
  std::vector<std::string> out;
  const std::string all = NIMBUS_MODULE_DIRS;
  std::size_t at = 0;
  while (at <= all.size()) {
    const std::size_t end = std::min(all.find(':', at), all.size());
    out.push_back(all.substr(at, end - at));
    at = end + 1;
  }
  return out;
}

struct Loaded {
  const VdbModule* module = nullptr;
  std::string error;
};

Loaded load() {
  Loaded out;
  try {
    using Entry = const VdbModule* (*)();
    const auto entry = reinterpret_cast<Entry>(
        load_module_entry(kVdbModuleFile, module_folders(), kVdbModuleVariable, kVdbModuleEntry));
    const VdbModule* m = entry();
    if (!m || m->version != kVdbModuleVersion || !m->read || !m->write)
      throw ModuleLoadError(std::string("cannot use ") + kVdbModuleFile +
                            ": it was built for another version of nimbus");
    out.module = m;
  } catch (const ModuleLoadError& e) {
    out.error = e.what();
  }
  return out;
}

}  // namespace

const VdbModule& vdb_module() {
  static const Loaded loaded = load();  // once, whichever thread asks first
  if (!loaded.module) throw ModuleLoadError(loaded.error);
  return *loaded.module;
}

}  // namespace nimbus
