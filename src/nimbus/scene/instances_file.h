#pragma once
// An object's instances from a side file (docs/scene-format.md, "instances"): a NumPy .npy
// array of transforms, the form that scripts write (numpy.save) and that a million instances
// fit in (a scene file holds at most 64 MiB of text, 145 MB for a million spheres).

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "nimbus/math/mat4.h"

namespace nimbus {

// The most instances one object may have: 1.3 GB of transforms in memory, far past any scene
// this machine renders, far below what a corrupt header could ask for.
inline constexpr std::size_t kMaxInstances = 10'000'000;

// A problem with the file, without its name (the caller names it and the key).
struct InstancesFileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Reads a .npy file (format version 1, 2 or 3) of little-endian float64 or float32 in C order,
// shaped (N, 3) — translations —, (N, 3, 4) — the top three rows of affine matrices — or
// (N, 4, 4) with each last row 0 0 0 1; 1 <= N <= kMaxInstances. The transforms are returned as
// read; their values are the caller's to check.
std::vector<Mat4> read_instances_file(const std::string& path);

}  // namespace nimbus
