#pragma once
// Reading one float grid from a .vdb (OpenVDB) or .nvdb (NanoVDB) file into NanoVDB's layout,
// cleaned for use as a density (vdb_density.h). The grid comes back type-erased so that this
// header, which is installed, names no OpenVDB or NanoVDB type. OpenVDB itself is called only by
// nimbus_openvdb.so (vdb_module.h), which the first read loads; vdb_file.cpp and vdb_density.cpp
// include NanoVDB's headers.

#include <cstdint>
#include <memory>
#include <string>

#include "nimbus/math/mat4.h"

namespace nimbus {

struct VdbFileGrid {
  std::shared_ptr<const void> owner;  // keeps the grid's memory (a NanoVDB grid handle) alive
  const void* grid = nullptr;         // the nanovdb::NanoGrid<float> in it
  Mat4 world_from_index;              // the grid's own transform (affine)
  std::uint64_t active_voxels = 0;
};

// Throws VdbError (vdb_density.h) for every way the file or grid can be unusable, and one of key
// "file" that names the module and dlerror's words when nimbus_openvdb.so cannot be loaded;
// `quantity`
// ("density", "temperature") is what the messages call the grid's values. `isolate`: read an
// OpenVDB file in a child process under limits (VdbParams::isolate_reader).
VdbFileGrid read_vdb_file(const std::string& file, const std::string& grid,
                          const std::string& quantity, bool isolate = true);

}  // namespace nimbus
