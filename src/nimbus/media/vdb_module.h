#pragma once
// The interface between nimbus and nimbus_openvdb.so, the shared module that holds every call
// into libopenvdb (issue 45): libopenvdb and its dependencies cost each process that links them a
// sixth of a second of symbol lookups in the dynamic loader, so only the processes that read or
// write a VDB file load them, through vdb_module() (os/shared_module.h). The interface is plain
// data, nimbus's own types and the standard library's: no OpenVDB or NanoVDB type, and no
// exception, crosses it. The module is built from vdb_module_openvdb.cpp, with the same compiler
// and standard library as nimbus, and is never unloaded (the grids it returns free their memory
// with its code).

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "nimbus/math/mat4.h"

namespace nimbus {

// Changes whenever a type below does: a module of another version is refused.
inline constexpr std::uint32_t kVdbModuleVersion = 1;
inline constexpr const char* kVdbModuleFile = "nimbus_openvdb.so";
inline constexpr const char* kVdbModuleEntry = "nimbus_openvdb_module";
// When set, the module's path (tests, and programs that embed nimbus away from its install).
inline constexpr const char* kVdbModuleVariable = "NIMBUS_OPENVDB_MODULE";

// OpenVDB's magic number (openvdb::OPENVDB_MAGIC; the module checks that they agree).
inline constexpr std::int32_t kOpenVdbMagic = 0x56444220;

enum class VdbFormat { OpenVdb, NanoVdb };

struct VdbReadRequest {
  std::string file, grid, quantity;  // as read_vdb_file (vdb_file.h)
  VdbFormat format = VdbFormat::OpenVdb;
};

// The grid read, cleaned and converted to NanoVDB (vdb_file.cpp), or why not.
struct VdbReadResult {
  enum class Status {
    Done,
    Failed,       // a VdbError: `key` ("file" or "grid") and `message`
    OutOfMemory,  // std::bad_alloc: while reading the file, `message` says so as a VdbError of
                  // key "file" (a damaged file); while converting the grid, `message` is ""
  };
  Status status = Status::Failed;
  std::string key, message;
  std::shared_ptr<const void> owner;  // keeps `grid` alive
  const void* grid = nullptr;         // a nanovdb::NanoGrid<float>, 32-byte aligned
  std::uint64_t grid_bytes = 0;       // its size: the grid is one block of memory
  Mat4 world_from_index;
  std::uint64_t active_voxels = 0;
};

// One leaf of an exported grid (io/vdb_export.h): 8³ voxels from `origin`, voxel (x, y, z) of the
// leaf at index 64 x + 8 y + z, as in OpenVDB's leaves. Inactive voxels hold 0.
struct VdbExportLeaf {
  std::array<int, 3> origin{};
  std::array<float, 512> values{};
  std::array<std::uint64_t, 8> active{};  // bit i % 64 of word i / 64: voxel i is active
};

struct VdbWriteRequest {
  std::string path;  // the file to write (the temporary file of write_atomically)
  const std::vector<VdbExportLeaf>* leaves = nullptr;  // those with an active voxel
  double voxel_size = 1;
  std::array<float, 3> sigma_a{}, sigma_s{};
  float phase_g = 0;
  std::string creator;
};

struct VdbModule {
  std::uint32_t version = 0;  // kVdbModuleVersion
  VdbReadResult (*read)(const VdbReadRequest& request) = nullptr;
  // "" when written, else the problem in one line.
  std::string (*write)(const VdbWriteRequest& request) = nullptr;
};

// The module, loaded on the first call (by any thread). Throws ModuleLoadError
// (os/shared_module.h), on this call and every later one, when it cannot be found, loaded, or is
// of another version.
const VdbModule& vdb_module();

}  // namespace nimbus

// The module's entry (extern "C": its name, kVdbModuleEntry, is what dlsym looks for), the one
// symbol it exports.
extern "C" __attribute__((visibility("default"))) const nimbus::VdbModule* nimbus_openvdb_module();
