#pragma once
// A density read from a VDB grid (issue 14): the clouds and smoke that Houdini, Blender, EmberGen
// or a simulation write as OpenVDB (.vdb) or NanoVDB (.nvdb) files.
//
// The density at a world point x is the grid's value trilinearly interpolated at x's index-space
// position, where index space is reached through the inverse of `transform` · (the grid's own
// index-to-world transform). Voxel (i, j, k) sits at index point (i, j, k), as in OpenVDB's
// samplers. Inactive voxels count as 0, as do negative values (a density is >= 0), so the
// density is 0 outside the active voxels and falls to 0 over one voxel at their edge.
//
// range() comes from the VDB tree itself, never from samples: a box maps to the index-space
// voxels whose values trilinear interpolation can blend anywhere in it (one voxel beyond the box
// on the upper side, across leaf borders too), and the bound is the minimum and maximum of those
// values, taken from the per-node and per-leaf extrema that NanoVDB stores wherever a node lies
// wholly inside that voxel range and from the voxels themselves where it lies partly. A box over
// empty tiles reads no voxel and bounds the density by 0, so the majorant octree marks it empty.
//
// The grid is read with OpenVDB, cleaned (inactive values and negative values to 0; leaves
// without active voxels dropped) and converted to NanoVDB, whose read accessor is the faster of
// the two for lookups that cannot keep an accessor between calls (docs/benchmarks.md, "VDB
// lookups"). No installed header names an OpenVDB or NanoVDB type.

#include <stdexcept>
#include <string>
#include <utility>

#include "nimbus/math/mat4.h"
#include "nimbus/media/density.h"

namespace nimbus {

struct VdbParams {
  std::string file;                   // a .vdb or .nvdb file (told apart by their magic numbers)
  std::string grid = "density";       // the grid's name in the file
  Mat4 transform = Mat4::identity();  // applied after the grid's index-to-world transform
  std::string quantity = "density";   // what the values are, in messages
  // Read a .vdb in a child process under memory and time limits (vdb_file.cpp), so that what
  // OpenVDB does with a damaged file cannot take the caller's memory or process down. Off only
  // where the reading itself is under test (the fuzzer needs its coverage in-process).
  bool isolate_reader = true;
};

// Why a file cannot serve as a density. `key` names the parameter at fault, "file" or "grid";
// what() is one line that names the file.
struct VdbError : std::runtime_error {
  VdbError(std::string key_, const std::string& problem)
      : std::runtime_error(problem), key(std::move(key_)) {}
  std::string key;
};

// Reads the grid and makes the density; throws VdbError for a missing or unreadable file, a file
// that is not VDB or is corrupted, a missing grid (listing those present), a grid that does not
// hold float or double values or is a level set, a transform that is not affine, and values
// that are not finite.
DensityPtr make_vdb_density(const VdbParams& params);

}  // namespace nimbus
