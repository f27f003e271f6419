#pragma once
// VDB files for the tests, written and read with OpenVDB's own API (tests/vdb_grids.cpp), so that
// nimbus's reader and exporter are checked against the library's files rather than its own. No
// OpenVDB type appears here and only vdb_grids.cpp includes OpenVDB: its headers take tens of
// seconds to compile, once rather than in every test that needs a grid.

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <map>
#include <optional>
#include <string>
#include <vector>

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

// A voxel's index (i, j, k); printed as "[i, j, k]", as OpenVDB prints its Coord.
struct Coord {
  int i = 0, j = 0, k = 0;
  constexpr int operator[](int axis) const { return axis == 0 ? i : (axis == 1 ? j : k); }
  friend bool operator==(const Coord&, const Coord&) = default;
};
std::ostream& operator<<(std::ostream& out, const Coord& c);

// A voxel and its value.
template <typename T>
struct Voxel {
  Coord ijk;
  T value;
};

// OpenVDB's grid classes (its GridClass), in its order.
enum class GridClass { kUnknown, kLevelSet, kFogVolume, kStaggered };

// An active tile of `value` at `level` of the tree (1: 8³ voxels, 2: 128³) from `origin`.
struct Tile {
  int level;
  Coord origin;
  float value;
};

// A float grid to write with write_vdb: background 0, the given active voxels and tiles, a
// linear transform of voxel size `voxel` with index (0, 0, 0) at the world origin.
// (Every member a designated initializer may leave out has an initializer: else GCC warns.)
struct FloatGrid {
  std::string name;
  std::vector<Voxel<float>> voxels = {};
  std::vector<Tile> tiles = {};
  double voxel = 1;
  GridClass grid_class = GridClass::kUnknown;
};

// Writes `file`: the grids, in order.
void write_vdb(const std::string& file, const std::vector<FloatGrid>& grids);

// Writes `file`: the grid with a frustum transform (OpenVDB's createFrustumTransform) over the
// index box [lo, hi], of the given taper and depth, instead of its linear one.
void write_frustum_vdb(const std::string& file, const FloatGrid& grid, const Vec3& lo,
                       const Vec3& hi, double taper, double depth);

// A double grid: its background and its active and inactive voxels; unit voxels.
struct DoubleGrid {
  std::string name;
  double background = 0;
  std::vector<Voxel<double>> active = {}, inactive = {};
};

// Writes `file`: the one double grid.
void write_double_vdb(const std::string& file, const DoubleGrid& grid);

// Writes `file`: a Vec3s grid named `name` whose one active voxel `ijk` holds `value`.
void write_vec3s_vdb(const std::string& file, const std::string& name, const Coord& ijk,
                     const Vec3& value);

// Writes `file`: a level set (OpenVDB's createLevelSetSphere) named `name`, a sphere of `radius`
// around the world origin in voxels of size `voxel`.
void write_level_set_sphere_vdb(const std::string& file, const std::string& name, double radius,
                                double voxel);

// Writes the NanoVDB file `nvdb`: the float grid "density" of the OpenVDB file `vdb`, converted.
void write_nvdb(const std::string& vdb, const std::string& nvdb);

// Writes the NanoVDB file `nvdb` as write_nvdb, but with every child offset of the root set to
// 2⁴⁰ bytes, far outside the grid.
void write_nvdb_with_wild_children(const std::string& vdb, const std::string& nvdb);

// Byte offsets in a NanoVDB file of one grid: the grid name's size (a uint32), and its name.
std::uint64_t nvdb_name_size_offset();
std::uint64_t nvdb_name_offset();

// A float grid read back from a file by read_float_grid: its properties, and lookups into the
// grid itself (which they hold).
struct ReadFloatGrid {
  GridClass grid_class = GridClass::kUnknown;
  float background = 0;
  bool linear = false;  // its transform
  Vec3 voxel_size;
  std::uint64_t active_voxel_count = 0, active_tile_count = 0;
  // Its active values in OpenVDB's order (cbeginValueOn): a voxel each, a tile once at its origin.
  std::vector<Voxel<float>> active;
  // Its metadata of type float and Vec3s, by name.
  std::map<std::string, float> float_metadata;
  std::map<std::string, std::array<float, 3>> vec3s_metadata;
  std::function<bool(const Coord&)> is_on;
  std::function<float(const Coord&)> value;  // also of inactive voxels
  std::function<Vec3(const Coord&)> index_to_world;
};

// Reads the grid `name` of `file`: none when it does not hold floats; throws when it is absent.
std::optional<ReadFloatGrid> read_float_grid(const std::string& file, const std::string& name);

// Reads `file`: the names of its grids, in order.
std::vector<std::string> vdb_grid_names(const std::string& file);

// Reads `file`: its own (not a grid's) metadata `name`, a string; throws when there is none.
std::string vdb_file_metadata(const std::string& file, const std::string& name);

}  // namespace nimbus::test
