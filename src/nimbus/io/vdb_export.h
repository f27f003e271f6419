#pragma once
// Writing a scene's medium as an OpenVDB fog volume (issue 14, `nimbus export-vdb`), for Houdini,
// Blender and any other tool that reads VDB.
//
// The grid is a float grid named "density" of grid class fog volume, with a linear transform of
// voxel size H: voxel (i, j, k) holds the medium's density (the scene format's "density" with
// its scale, before sigma_a and sigma_s) at the world point (i H, j H, k H), for the voxels whose
// centres lie in the object's bounds; where the object's F <= 0 there is no medium, 0. Voxels
// whose density is below kVdbExportThreshold times the grid's largest value stay inactive, so
// the file is sparse. The medium's sigma_a and sigma_s (linear sRGB, as vec3s) and its phase
// asymmetry g (float, "phase_g") go along as grid metadata. The grid is built by oneTBB over
// blocks of 8³ voxels (one leaf each); a block whose interval bound shows no medium costs no
// lookup.

#include <cstdint>
#include <string>

#include "nimbus/media/octree.h"
#include "nimbus/render/scene.h"
#include "nimbus/scene/scene_desc.h"

namespace nimbus {

inline constexpr double kVdbExportThreshold = 1e-4;
// The most voxels an export may cover (the object's bounds over H³): each costs a lookup unless
// its block is culled, so more would run for an hour.
inline constexpr double kVdbExportMaxVoxels = 4.0e9;
// The voxel sizes an export accepts, whatever the scene. OpenVDB's linear transform refuses a
// scale whose cube is below 3e-15 (H < 1.44e-5: "Non-zero scale values required"); a reader
// needs the transform's determinant H³ finite (nimbus's vdb density refuses it otherwise), and
// 1e100, the scene format's largest length, keeps it so (1e300).
inline constexpr double kVdbExportMinVoxelSize = 1.5e-5;
inline constexpr double kVdbExportMaxVoxelSize = 1e100;

// What is wrong with a voxel size outside [kVdbExportMinVoxelSize, kVdbExportMaxVoxelSize]
// ("must be in [1.5e-05, 1e+100], not 1e+300"), or "" for one inside.
std::string vdb_voxel_size_problem(double voxel_size);

struct VdbExportResult {
  std::uint64_t active_voxels = 0;
  double max_density = 0;  // the largest value written
  bool cancelled = false;  // the monitor cancelled: nothing was written
};

// The object to export: `requested` (an index into desc.objects), or -1 for the first object
// that holds a medium. Throws std::invalid_argument with a one-line message when there is no
// such object or it holds no medium.
int vdb_export_object(const SceneDesc& desc, int requested);

// The compiled scene's index of the description's object `object` (SceneObject::source); throws
// std::invalid_argument when compiling dropped it (an empty shape).
int vdb_export_compiled(const Scene& scene, int object);

// The number of voxel centres i H inside the object's bounds.
double vdb_export_voxels(const Scene& scene, int object, double voxel_size);

// Builds the grid of `object` (which holds a medium) and writes it to `path` atomically
// (io/atomic_file.h); the monitor sees the fraction of blocks done and may cancel. Throws
// std::invalid_argument, with nothing written, for a voxel size outside the range above, one
// that gives more than kVdbExportMaxVoxels voxels or none in the object's bounds, or a grid
// without an active voxel; std::runtime_error("PATH: problem") when the file cannot be written.
VdbExportResult export_vdb(const Scene& scene, int object, double voxel_size,
                           const std::string& path, const BuildMonitor& monitor = {});

}  // namespace nimbus
