// The VDB files of the tests (support/vdb_grids.h), written and read with OpenVDB; the one test
// file that includes OpenVDB's and NanoVDB's headers.

#include "support/vdb_grids.h"

#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <ostream>

namespace nimbus::test {
namespace {

static_assert(int(GridClass::kUnknown) == openvdb::GRID_UNKNOWN &&
              int(GridClass::kLevelSet) == openvdb::GRID_LEVEL_SET &&
              int(GridClass::kFogVolume) == openvdb::GRID_FOG_VOLUME &&
              int(GridClass::kStaggered) == openvdb::GRID_STAGGERED);

openvdb::Coord coord(const Coord& c) {
  return {c.i, c.j, c.k};
}

Coord coord(const openvdb::Coord& c) {
  return {c.x(), c.y(), c.z()};
}

void write_grids(const std::string& file, const openvdb::GridPtrVec& grids) {
  openvdb::initialize();
  openvdb::io::File(file).write(grids);
}

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

openvdb::FloatGrid::Ptr make_float_grid(const FloatGrid& spec) {
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
  grid->setName(spec.name);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(spec.voxel));
  // Only a class other than unknown is written as metadata, as OpenVDB's own grids do.
  if (spec.grid_class != GridClass::kUnknown)
    grid->setGridClass(openvdb::GridClass(spec.grid_class));
  auto acc = grid->getAccessor();
  for (const Voxel<float>& v : spec.voxels) acc.setValueOn(coord(v.ijk), v.value);
  for (const Tile& t : spec.tiles) grid->tree().addTile(t.level, coord(t.origin), t.value, true);
  return grid;
}

// The float grid "density" of the OpenVDB file `vdb` as NanoVDB.
nanovdb::GridHandle<> nanovdb_of(const std::string& vdb) {
  openvdb::initialize();
  openvdb::io::File f(vdb);
  f.open();
  return nanovdb::openToNanoVDB(*openvdb::gridPtrCast<openvdb::FloatGrid>(f.readGrid("density")));
}

}  // namespace

std::ostream& operator<<(std::ostream& out, const Coord& c) {
  return out << coord(c);
}

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

void write_vdb(const std::string& file, const std::vector<FloatGrid>& grids) {
  openvdb::GridPtrVec made;
  for (const FloatGrid& g : grids) made.push_back(make_float_grid(g));
  write_grids(file, made);
}

void write_frustum_vdb(const std::string& file, const FloatGrid& grid, const Vec3& lo,
                       const Vec3& hi, double taper, double depth) {
  openvdb::FloatGrid::Ptr g = make_float_grid(grid);
  g->setTransform(openvdb::math::Transform::createFrustumTransform(
      openvdb::BBoxd({lo.x, lo.y, lo.z}, {hi.x, hi.y, hi.z}), taper, depth));
  write_grids(file, {g});
}

void write_double_vdb(const std::string& file, const DoubleGrid& grid) {
  openvdb::DoubleGrid::Ptr g = openvdb::DoubleGrid::create(grid.background);
  for (const Voxel<double>& v : grid.active) g->tree().setValueOn(coord(v.ijk), v.value);
  for (const Voxel<double>& v : grid.inactive) g->tree().setValueOff(coord(v.ijk), v.value);
  g->setName(grid.name);
  write_grids(file, {g});
}

void write_vec3s_vdb(const std::string& file, const std::string& name, const Coord& ijk,
                     const Vec3& value) {
  openvdb::Vec3SGrid::Ptr g = openvdb::Vec3SGrid::create();
  g->tree().setValueOn(coord(ijk), openvdb::Vec3s(float(value.x), float(value.y), float(value.z)));
  g->setName(name);
  write_grids(file, {g});
}

void write_level_set_sphere_vdb(const std::string& file, const std::string& name, double radius,
                                double voxel) {
  openvdb::initialize();
  auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(float(radius), {0, 0, 0},
                                                                         float(voxel));
  sphere->setName(name);
  write_grids(file, {sphere});
}

void write_nvdb(const std::string& vdb, const std::string& nvdb) {
  nanovdb::io::writeGrid(nvdb, nanovdb_of(vdb));
}

void write_nvdb_with_wild_children(const std::string& vdb, const std::string& nvdb) {
  nanovdb::GridHandle<> handle = nanovdb_of(vdb);
  auto* root = handle.grid<float>()->tree().root().data();
  for (uint32_t i = 0; i < root->mTableSize; ++i)
    if (root->tile(i)->isChild()) root->tile(i)->child = int64_t(1) << 40;
  nanovdb::io::writeGrid(nvdb, handle);
}

std::uint64_t nvdb_name_size_offset() {
  return sizeof(nanovdb::io::Header) + offsetof(nanovdb::io::MetaData, nameSize);
}

std::uint64_t nvdb_name_offset() {
  return sizeof(nanovdb::io::Header) + sizeof(nanovdb::io::MetaData);
}

std::optional<ReadFloatGrid> read_float_grid(const std::string& file, const std::string& name) {
  openvdb::initialize();
  openvdb::io::File f(file);
  f.open();
  const openvdb::FloatGrid::ConstPtr grid =
      openvdb::gridPtrCast<openvdb::FloatGrid>(f.readGrid(name));
  if (!grid) return std::nullopt;
  ReadFloatGrid r;
  r.grid_class = GridClass(grid->getGridClass());
  r.background = grid->background();
  r.linear = grid->transform().isLinear();
  const openvdb::Vec3d size = grid->voxelSize();
  r.voxel_size = {size[0], size[1], size[2]};
  r.active_voxel_count = grid->activeVoxelCount();
  r.active_tile_count = grid->tree().activeTileCount();
  for (auto v = grid->cbeginValueOn(); v; ++v) r.active.push_back({coord(v.getCoord()), *v});
  for (auto m = grid->beginMeta(); m != grid->endMeta(); ++m) {
    if (const auto s = openvdb::DynamicPtrCast<openvdb::FloatMetadata>(m->second))
      r.float_metadata[m->first] = s->value();
    if (const auto v = openvdb::DynamicPtrCast<openvdb::Vec3SMetadata>(m->second))
      r.vec3s_metadata[m->first] = {v->value()[0], v->value()[1], v->value()[2]};
  }
  // Unregistered accessors: the grid they point into may go before them (a closure destroys its
  // captures in no set order), and they never see it change.
  r.is_on = [grid, acc = grid->getConstUnsafeAccessor()](const Coord& c) {
    return acc.isValueOn(coord(c));
  };
  r.value = [grid, acc = grid->getConstUnsafeAccessor()](const Coord& c) {
    return acc.getValue(coord(c));
  };
  r.index_to_world = [grid](const Coord& c) {
    const openvdb::Vec3d w = grid->indexToWorld(coord(c));
    return Vec3{w[0], w[1], w[2]};
  };
  return r;
}

std::vector<std::string> vdb_grid_names(const std::string& file) {
  openvdb::initialize();
  openvdb::io::File f(file);
  f.open();
  std::vector<std::string> names;
  for (auto n = f.beginName(); n != f.endName(); ++n) names.push_back(*n);
  return names;
}

std::string vdb_file_metadata(const std::string& file, const std::string& name) {
  openvdb::initialize();
  openvdb::io::File f(file);
  f.open();
  return f.getMetadata()->metaValue<std::string>(name);
}

}  // namespace nimbus::test
