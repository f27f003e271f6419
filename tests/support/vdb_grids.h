#pragma once
// VDB files for the tests, written with OpenVDB's own API (tests/vdb_grids.cpp), so that nimbus's
// reader is checked against the library's files rather than its own. No OpenVDB type appears
// here: only vdb_grids.cpp and the tests that build special grids include OpenVDB.

#include <filesystem>
#include <string>

#include "nimbus/math/vec3.h"

namespace nimbus::test {

// A fresh directory under the system's temporary directory, removed with everything in it.
class TempDir {
 public:
  explicit TempDir(const std::string& name);
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// The value of the linear grid at voxel (i, j, k): exact in float, and > 0 from -4 up.
inline double linear_value(double i, double j, double k) {
  return 4 + 0.5 * i + 0.25 * j + 0.125 * k;
}

// A float fog volume named "density" whose voxels (i, j, k) in [lo, hi]³ are active and hold
// linear_value(i, j, k); voxel size `voxel`, index (0, 0, 0) at world `offset`.
void write_linear_vdb(const std::string& file, int lo, int hi, double voxel, const Vec3& offset);

// A float fog volume named "density": a ball of `radius` voxels around index (0, 0, 0) whose
// density falls from 1 at the centre to 0 at the edge, rippled so that leaves differ, and all
// else empty; voxel size `voxel`, index (0, 0, 0) at world `center`.
void write_ball_vdb(const std::string& file, int radius, double voxel, const Vec3& center);

// The ball's voxel value at (i, j, k) (0 outside it, inactive there).
double ball_value(int i, int j, int k, int radius);

}  // namespace nimbus::test
