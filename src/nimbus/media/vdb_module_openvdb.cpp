// nimbus_openvdb.so (media/vdb_module.h): every call of nimbus into libopenvdb, in a shared
// module that nimbus loads with dlopen when a scene reads a VDB file or `nimbus export-vdb` writes
// one (issue 45). Reading: a grid from a .vdb (OpenVDB) or .nvdb (NanoVDB) file, cleaned for use
// as a density and converted to NanoVDB (media/vdb_file.h). Writing: the leaves that
// io/vdb_export.cpp built, as an OpenVDB fog volume. Nothing here throws past the interface.

// First: Debian's nanovdb/util/GridValidator.h uses std::cerr without including <iostream>.
#include <iostream>
// Then the libraries and the standard library.

#include <fmt/format.h>
#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/GridHandle.h>
#include <nanovdb/util/GridValidator.h>
#include <nanovdb/util/IO.h>
#include <nanovdb/util/NanoToOpenVDB.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <new>
#include <stdexcept>
#include <vector>

#include "nimbus/media/vdb_module.h"

namespace nimbus {
namespace {

namespace fs = std::filesystem;

static_assert(kOpenVdbMagic == openvdb::OPENVDB_MAGIC);

// A problem with the file (`key` "file") or the grid ("grid"), as VdbError (vdb_density.h) says
// it; it becomes a VdbReadResult at the interface.
struct VdbError : std::runtime_error {
  VdbError(std::string key_, const std::string& problem)
      : std::runtime_error(problem), key(std::move(key_)) {}
  std::string key;
};

// The libraries' messages may span lines (NanoVDB's version check does); an error is one line.
std::string one_line(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const bool space = std::isspace(static_cast<unsigned char>(c));
    if (!space)
      out += c;
    else if (!out.empty() && out.back() != ' ')
      out += ' ';
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

[[noreturn]] void fail_file(const std::string& file, const std::string& problem) {
  throw VdbError("file", fmt::format("{}: {}", file, one_line(problem)));
}

[[noreturn]] void fail_grid(const std::string& file, const std::string& grid,
                            const std::string& problem) {
  throw VdbError("grid", fmt::format("{}: grid \"{}\" {}", file, grid, one_line(problem)));
}

// "the file holds grids "a", "b"" or "the file holds no grid".
std::string holds(const std::vector<std::string>& names) {
  if (names.empty()) return "the file holds no grid";
  std::string list;
  for (const std::string& n : names) list += fmt::format("{}\"{}\"", list.empty() ? "" : ", ", n);
  return fmt::format("the file holds {} {}", names.size() == 1 ? "grid" : "grids", list);
}

// The grid as a density reads it, in a new float grid with background 0: active values copied
// (negative ones as 0), inactive voxels and tiles 0, leaves without active voxels dropped, so that
// every node left holds active values and its extrema are those range() needs.
template <class GridT>
openvdb::FloatGrid::Ptr cleaned(const GridT& in, const std::string& file, const std::string& name,
                                const std::string& quantity) {
  openvdb::FloatGrid::Ptr out = openvdb::FloatGrid::create(0.0f);
  out->setTransform(in.transform().copy());
  openvdb::FloatTree& tree = out->tree();
  const auto density = [&](double v, const openvdb::Coord& at) {
    const float f = static_cast<float>(std::max(v, 0.0));
    if (!std::isfinite(v) || !std::isfinite(f))
      fail_grid(file, name,
                fmt::format("holds the value {} at voxel ({}, {}, {}); a {} must be finite", v,
                            at.x(), at.y(), at.z(), quantity));
    return f;
  };
  for (auto leaf = in.tree().cbeginLeaf(); leaf; ++leaf) {
    if (leaf->isEmpty()) continue;
    auto copy = std::make_unique<openvdb::FloatTree::LeafNodeType>(leaf->origin(), 0.0f);
    for (auto v = leaf->cbeginValueOn(); v; ++v)
      copy->setValueOn(v.pos(), density(*v, v.getCoord()));
    tree.addLeaf(copy.release());
  }
  for (auto tile = in.tree().cbeginValueOn(); tile; ++tile)
    if (!tile.isVoxelValue())
      tree.addTile(tile.getLevel(), tile.getCoord(), density(*tile, tile.getCoord()), true);
  return out;
}

// The checks that need only the grid's metadata: a float or double fog volume with a linear
// transform.
void check_grid(const openvdb::GridBase& g, const std::string& file, const std::string& name,
                const std::string& quantity) {
  if (!g.isType<openvdb::FloatGrid>() && !g.isType<openvdb::DoubleGrid>())
    fail_grid(file, name,
              fmt::format("holds {} values; a {} grid holds float or double values", g.valueType(),
                          quantity));
  if (g.getGridClass() == openvdb::GRID_LEVEL_SET)
    fail_grid(file, name,
              fmt::format("is a level set (signed distances), not a {}; convert it to a fog "
                          "volume first (OpenVDB's tools::sdfToFogVolume)",
                          quantity));
  if (!g.transform().isLinear())
    fail_grid(file, name,
              fmt::format("has a non-linear transform ({}); only linear (affine) grid "
                          "transforms are supported",
                          g.transform().mapType()));
}

openvdb::FloatGrid::Ptr read_openvdb(const std::string& file, const std::string& name,
                                     const std::string& quantity) {
  openvdb::io::File f(file);
  try {
    f.open(/*delayLoad=*/false);
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    fail_file(file, fmt::format("not a readable OpenVDB file ({})", e.what()));
  }
  std::vector<std::string> names;
  for (auto it = f.beginName(); it != f.endName(); ++it) names.push_back(*it);
  if (!f.hasGrid(name)) fail_grid(file, name, fmt::format("is not in the file ({})", holds(names)));
  check_grid(*f.readGridMetadata(name), file, name, quantity);
  const openvdb::GridBase::Ptr grid = f.readGrid(name);
  f.close();
  if (const auto g = openvdb::gridConstPtrCast<openvdb::FloatGrid>(grid))
    return cleaned(*g, file, name, quantity);
  return cleaned(*openvdb::gridConstPtrCast<openvdb::DoubleGrid>(grid), file, name, quantity);
}

// Whether every node of a NanoVDB grid lies inside its buffer, 32-byte aligned: a corrupted file
// could otherwise send the conversion through wild offsets. (NanoVDB's own GridValidator skips
// the leaves.)
template <class T>
bool nano_nodes_inside(const nanovdb::NanoGrid<T>& grid, std::uint64_t size) {
  const auto base = reinterpret_cast<std::uintptr_t>(&grid);
  const auto inside = [&](const void* p, std::uint64_t bytes) {
    const auto at = reinterpret_cast<std::uintptr_t>(p);
    return at >= base && bytes <= size && at - base <= size - bytes &&
           at % NANOVDB_DATA_ALIGNMENT == 0;
  };
  if (grid.gridSize() > size || !inside(&grid.tree(), sizeof(grid.tree()))) return false;
  const auto& root = grid.tree().root();
  if (!inside(&root, sizeof(root)) || !inside(&root, root.memUsage())) return false;
  for (std::uint32_t i = 0; i < root.tileCount(); ++i) {
    const auto* tile = root.data()->tile(i);
    if (!tile->isChild()) continue;
    const auto* upper = root.data()->getChild(tile);
    if (!inside(upper, sizeof(*upper))) return false;
    for (auto n = upper->childMask().beginOn(); n; ++n) {
      const auto* lower = upper->data()->getChild(*n);
      if (!inside(lower, sizeof(*lower))) return false;
      for (auto m = lower->childMask().beginOn(); m; ++m)
        if (!inside(lower->data()->getChild(*m), sizeof(nanovdb::NanoLeaf<T>))) return false;
    }
  }
  return true;
}

template <class T>
openvdb::FloatGrid::Ptr nano_to_cleaned(const nanovdb::GridHandle<>& handle,
                                        const std::string& file, const std::string& name,
                                        const std::string& quantity) {
  const nanovdb::NanoGrid<T>* grid = handle.grid<T>();
  if (!grid) fail_file(file, fmt::format("grid \"{}\" could not be read (corrupted file)", name));
  if (!nano_nodes_inside(*grid, handle.size()))
    fail_file(file, "corrupted NanoVDB file (a node lies outside its grid)");
  if (const std::string problem = nanovdb::GridValidator<T>::check(*grid, /*detailed=*/false);
      !problem.empty())
    fail_file(file, fmt::format("corrupted NanoVDB file ({})", problem));
  const auto open = nanovdb::nanoToOpenVDB(*grid);
  check_grid(*open, file, name, quantity);
  return cleaned(*open, file, name, quantity);
}

// NanoVDB's readGridMetaData trusts each grid's name: it allocates the name's stated length and
// reads it with strlen, so a damaged header makes it allocate gigabytes or read past its buffer
// (found by fuzz/vdb_fuzzer.cpp). The segments are walked here first, as that function walks
// them, with every length checked against the file; a bad magic number is left to the library.
void check_nanovdb_headers(const std::string& file) {
  std::error_code ec;
  const std::uint64_t size = fs::file_size(file, ec);
  if (ec) fail_file(file, fmt::format("cannot read file ({})", ec.message()));
  std::ifstream in(file, std::ios::binary);
  std::uint64_t at = 0;
  while (size - at >= sizeof(nanovdb::io::Header)) {
    nanovdb::io::Header header;
    in.read(reinterpret_cast<char*>(&header), sizeof header);
    at += sizeof header;
    if (!in || header.magic != NANOVDB_MAGIC_NUMBER) return;
    if (header.version.getMajor() != NANOVDB_MAJOR_VERSION_NUMBER)
      fail_file(file, fmt::format("written by NanoVDB {}.{}.{}; this build of nimbus reads files "
                                  "of NanoVDB {}.x",
                                  header.version.getMajor(), header.version.getMinor(),
                                  header.version.getPatch(), NANOVDB_MAJOR_VERSION_NUMBER));
    std::uint64_t data = 0;
    for (int g = 0; g < header.gridCount; ++g) {
      nanovdb::io::MetaData meta;
      if (size - at < sizeof meta)
        fail_file(file, "corrupted NanoVDB file (a grid's header is cut short)");
      in.read(reinterpret_cast<char*>(&meta), sizeof meta);
      at += sizeof meta;
      if (meta.nameSize == 0 || meta.nameSize > size - at)
        fail_file(file, "corrupted NanoVDB file (a grid's name runs past the end of the file)");
      std::string grid_name(meta.nameSize, '\0');
      in.read(grid_name.data(), meta.nameSize);
      if (grid_name.find('\0') == std::string::npos)
        fail_file(file, "corrupted NanoVDB file (a grid's name is not terminated)");
      at += meta.nameSize;
      if (meta.fileSize > size)
        fail_file(file, "corrupted NanoVDB file (a grid is larger than the file)");
      data += meta.fileSize;
    }
    if (data > size - at)
      fail_file(file, "corrupted NanoVDB file (a grid is larger than the file)");
    at += data;
    in.seekg(static_cast<std::streamoff>(at));
  }
}

openvdb::FloatGrid::Ptr read_nanovdb(const std::string& file, const std::string& name,
                                     const std::string& quantity) {
  check_nanovdb_headers(file);
  std::vector<nanovdb::io::GridMetaData> grids;
  try {
    grids = nanovdb::io::readGridMetaData(file);
  } catch (const std::exception& e) {
    fail_file(file, fmt::format("not a readable NanoVDB file ({})", e.what()));
  }
  std::vector<std::string> names;
  const nanovdb::io::GridMetaData* meta = nullptr;
  for (const auto& g : grids) {
    names.push_back(g.gridName);
    if (g.gridName == name && !meta) meta = &g;
  }
  if (!meta) fail_grid(file, name, fmt::format("is not in the file ({})", holds(names)));
  const nanovdb::GridType type = meta->gridType;
  if (type != nanovdb::GridType::Float && type != nanovdb::GridType::Double)
    fail_grid(file, name,
              fmt::format("holds {} values; a {} grid holds float or double values",
                          nanovdb::toStr(type), quantity));
  if (meta->gridClass == nanovdb::GridClass::LevelSet)
    fail_grid(file, name,
              fmt::format("is a level set (signed distances), not a {}; convert it to a fog "
                          "volume first",
                          quantity));
  if (meta->codec != nanovdb::io::Codec::NONE)
    fail_file(file, fmt::format("grid \"{}\" is compressed ({}); nimbus reads uncompressed .nvdb "
                                "files (nanovdb_convert without -z or -b)",
                                name, nanovdb::io::toStr(meta->codec)));
  std::error_code ec;
  if (meta->gridSize > fs::file_size(file, ec) || ec)
    fail_file(file, "corrupted NanoVDB file (a grid is larger than the file)");
  nanovdb::GridHandle<> handle;
  try {
    handle = nanovdb::io::readGrid(file, name);
  } catch (const std::exception& e) {
    fail_file(file, fmt::format("corrupted NanoVDB file ({})", e.what()));
  }
  return type == nanovdb::GridType::Float ? nano_to_cleaned<float>(handle, file, name, quantity)
                                          : nano_to_cleaned<double>(handle, file, name, quantity);
}

// The affine map from index space to the grid's world space, from the images of the origin and
// the unit vectors (OpenVDB's matrices act on row vectors; this avoids depending on that).
Mat4 world_from_index(const openvdb::math::Transform& t) {
  const openvdb::Vec3d o = t.indexToWorld(openvdb::Vec3d(0, 0, 0));
  Mat4 m;  // Mat4::identity() is nimbus's code, not the module's
  m(3, 3) = 1;
  for (int c = 0; c < 3; ++c) {
    openvdb::Vec3d e(0, 0, 0);
    e[c] = 1;
    const openvdb::Vec3d image = t.indexToWorld(e) - o;
    for (int r = 0; r < 3; ++r) m(r, c) = image[r];
  }
  for (int r = 0; r < 3; ++r) m(r, 3) = o[r];
  return m;
}

// The grid of the request, cleaned and converted to NanoVDB; VdbError or a library's exception
// when it cannot be.
// `reading` stays true while the file is read, and is false once the grid is converted.
VdbReadResult read_grid(const VdbReadRequest& r, bool& reading) {
  openvdb::initialize();  // registers the grid types; cheap after the first call
  const bool nano = r.format == VdbFormat::NanoVdb;
  openvdb::FloatGrid::Ptr grid;
  try {
    grid =
        nano ? read_nanovdb(r.file, r.grid, r.quantity) : read_openvdb(r.file, r.grid, r.quantity);
  } catch (const VdbError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    // Past the header, a library's exception means data it could not decode.
    fail_file(r.file,
              fmt::format("corrupted {} file ({})", nano ? "NanoVDB" : "OpenVDB", e.what()));
  }
  reading = false;
  auto handle = std::make_shared<nanovdb::GridHandle<>>(
      nanovdb::openToNanoVDB(*grid, nanovdb::StatsMode::MinMax, nanovdb::ChecksumMode::Disable));
  VdbReadResult out;
  out.status = VdbReadResult::Status::Done;
  out.grid = handle->grid<float>();
  out.grid_bytes = handle->size();
  out.owner = std::move(handle);
  out.world_from_index = world_from_index(grid->transform());
  out.active_voxels = grid->activeVoxelCount();
  return out;
}

VdbReadResult read(const VdbReadRequest& r) {
  VdbReadResult out;
  bool reading = true;
  try {
    return read_grid(r, reading);
  } catch (const VdbError& e) {
    out.status = VdbReadResult::Status::Failed;
    out.key = e.key;
    out.message = e.what();
  } catch (const std::bad_alloc& e) {
    out.status = VdbReadResult::Status::OutOfMemory;
    out.key = "file";
    if (reading)
      out.message = fmt::format("{}: corrupted {} file ({})", r.file,
                                r.format == VdbFormat::NanoVdb ? "NanoVDB" : "OpenVDB", e.what());
  } catch (const std::exception& e) {
    out.status = VdbReadResult::Status::Failed;
    out.key = "file";
    out.message = fmt::format("{}: cannot read the grid ({})", r.file, one_line(e.what()));
  }
  return out;
}

openvdb::Vec3s to_vec3s(const std::array<float, 3>& c) {
  return openvdb::Vec3s(c[0], c[1], c[2]);
}

std::string write(const VdbWriteRequest& r) {
  try {
    openvdb::initialize();
    using Leaf = openvdb::FloatTree::LeafNodeType;
    static_assert(Leaf::DIM == 8 && Leaf::SIZE == 512);
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    for (const VdbExportLeaf& in : *r.leaves) {
      const openvdb::Coord origin(in.origin[0], in.origin[1], in.origin[2]);
      auto leaf = std::make_unique<Leaf>(origin, 0.0f);
      for (openvdb::Index i = 0; i < Leaf::SIZE; ++i)
        if (in.active[i / 64] >> (i % 64) & 1)
          leaf->setValueOn(origin + openvdb::Coord(int(i >> 6), int(i >> 3 & 7), int(i & 7)),
                           in.values[i]);
      if (!leaf->isEmpty()) grid->tree().addLeaf(leaf.release());
    }
    grid->setName("density");
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(r.voxel_size));
    grid->insertMeta("sigma_a", openvdb::Vec3SMetadata(to_vec3s(r.sigma_a)));
    grid->insertMeta("sigma_s", openvdb::Vec3SMetadata(to_vec3s(r.sigma_s)));
    grid->insertMeta("phase_g", openvdb::FloatMetadata(r.phase_g));
    openvdb::MetaMap file_meta;
    file_meta.insertMeta("creator", openvdb::StringMetadata(r.creator));
    openvdb::io::File file(r.path);
    file.write({grid}, file_meta);
    file.close();
    return {};
  } catch (const std::exception& e) {
    return one_line(e.what());
  }
}

const VdbModule kModule{kVdbModuleVersion, &read, &write};

}  // namespace
}  // namespace nimbus

// Called once, by the process that loads the module, before any read: OpenVDB registers its grid
// types here, in that process, and not first in the child that reads a file (vdb_file.cpp), where
// its registration crashes under the child's limits.
extern "C" const nimbus::VdbModule* nimbus_openvdb_module() {
  openvdb::initialize();
  return &nimbus::kModule;
}
