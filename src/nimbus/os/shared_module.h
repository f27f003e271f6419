#pragma once
// Loading a shared module of nimbus (a CMake MODULE library, such as nimbus_openvdb.so) with
// dlopen when it is first needed, so that the libraries behind it (libopenvdb and its
// dependencies: a sixth of a second of the dynamic loader's symbol lookups, issue 45) load only
// in the processes that use them. A module is looked for beside the executable or shared library
// that holds nimbus's code (the nimbus executable, the tests, the Python module _core*.so), in
// folders given relative to that one, and then in absolute folders (the install's libdir).

#include <stdexcept>
#include <string>
#include <vector>

namespace nimbus {

// Why a module cannot be used, in one line that names the file: "cannot load
// /x/nimbus_openvdb.so (libopenvdb.so.10.0: cannot open shared object file: ...)".
struct ModuleLoadError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The folder of the executable or shared object that holds this code ("" if it cannot be told).
std::string folder_of_this_binary();

// dlopens `file_name` from the first of `folders` that holds it (a relative folder is taken from
// folder_of_this_binary()) and returns the address of its symbol `entry`. With a non-empty
// `override_variable` set in the environment, that variable's value is the module's path and no
// folder is searched. Throws ModuleLoadError when no folder holds the file, dlopen fails (dlerror
// in the message) or the entry is missing. The module is never unloaded.
void* load_module_entry(const std::string& file_name, const std::vector<std::string>& folders,
                        const char* override_variable, const char* entry);

}  // namespace nimbus
