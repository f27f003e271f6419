// The VDB files of the tests (support/vdb_grids.h), written with OpenVDB.

#include "support/vdb_grids.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <unistd.h>

#include <cmath>

namespace nimbus::test {
namespace {

void write_fog_volume(const std::string& file, openvdb::FloatGrid::Ptr grid, double voxel,
                      const Vec3& offset) {
  openvdb::initialize();
  auto transform = openvdb::math::Transform::createLinearTransform(voxel);
  transform->postTranslate(openvdb::Vec3d(offset.x, offset.y, offset.z));
  grid->setTransform(transform);
  grid->setName("density");
  grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  openvdb::io::File(file).write({grid});
}

}  // namespace

TempDir::TempDir(const std::string& name)
    : path_(std::filesystem::temp_directory_path() /
            ("nimbus_" + name + "_" + std::to_string(::getpid()))) {
  std::filesystem::remove_all(path_);
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

void write_linear_vdb(const std::string& file, int lo, int hi, double voxel, const Vec3& offset) {
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
  auto acc = grid->getAccessor();
  for (int i = lo; i <= hi; ++i)
    for (int j = lo; j <= hi; ++j)
      for (int k = lo; k <= hi; ++k) acc.setValue({i, j, k}, float(linear_value(i, j, k)));
  write_fog_volume(file, grid, voxel, offset);
}

double ball_value(int i, int j, int k, int radius) {
  const double r2 = double(i * i + j * j + k * k) / (double(radius) * radius);
  if (r2 >= 1) return 0;
  const double ripple = 0.75 + 0.25 * std::sin(0.7 * i) * std::cos(0.5 * j + 0.3 * k);
  return float((1 - r2) * ripple);
}

void write_ball_vdb(const std::string& file, int radius, double voxel, const Vec3& center) {
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
  auto acc = grid->getAccessor();
  for (int i = -radius; i <= radius; ++i)
    for (int j = -radius; j <= radius; ++j)
      for (int k = -radius; k <= radius; ++k)
        if (const double v = ball_value(i, j, k, radius); v > 0) acc.setValue({i, j, k}, float(v));
  write_fog_volume(file, grid, voxel, center);
}

}  // namespace nimbus::test
