#include "nimbus/os/shared_module.h"

#include <dlfcn.h>
#include <link.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

namespace nimbus {
namespace {

namespace fs = std::filesystem;

bool is_file(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::string last_dlerror() {
  const char* e = ::dlerror();
  return e ? e : "unknown error";
}

void* open_and_find(const std::string& path, const char* entry) {
  // RTLD_LOCAL: the module's libraries serve the module only; RTLD_NOW: a missing symbol is an
  // error here, not a crash at the first call.
  void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) throw ModuleLoadError("cannot load " + path + " (" + last_dlerror() + ")");
  void* symbol = ::dlsym(handle, entry);
  if (!symbol)
    throw ModuleLoadError("cannot load " + path + " (no entry " + entry + ": " + last_dlerror() +
                          ")");
  return symbol;
}

}  // namespace

std::string folder_of_this_binary() {
  Dl_info info;
  link_map* map = nullptr;
  if (::dladdr1(reinterpret_cast<const void*>(&folder_of_this_binary), &info,
                reinterpret_cast<void**>(&map), RTLD_DL_LINKMAP) != 0 &&
      map && map->l_name && map->l_name[0] != '\0') {
    std::error_code ec;
    const fs::path p = fs::canonical(map->l_name, ec);
    if (!ec) return p.parent_path().string();
  }
  // The main program (its link map has no name): the executable itself.
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : exe.parent_path().string();
}

void* load_module_entry(const std::string& file_name, const std::vector<std::string>& folders,
                        const char* override_variable, const char* entry) {
  if (override_variable && *override_variable)
    if (const char* path = std::getenv(override_variable); path && *path) {
      if (!is_file(path))
        throw ModuleLoadError(std::string("cannot load ") + path + " (no such file; set by " +
                              override_variable + ")");
      return open_and_find(path, entry);
    }
  const std::string here = folder_of_this_binary();
  std::string tried;
  for (const std::string& folder : folders) {
    if (folder.empty()) continue;
    fs::path dir(folder);
    if (dir.is_relative()) {
      if (here.empty()) continue;
      dir = fs::path(here) / dir;
    }
    const std::string path = (dir / file_name).lexically_normal().string();
    if (is_file(path)) return open_and_find(path, entry);
    if (tried.find(path) == std::string::npos) tried += (tried.empty() ? "" : ", ") + path;
  }
  throw ModuleLoadError("cannot load " + file_name + " (not found; looked for " +
                        (tried.empty() ? std::string("none") : tried) + ")");
}

}  // namespace nimbus
