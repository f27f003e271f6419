#include "nimbus/media/vdb_file.h"

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
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

#include "nimbus/media/isolated_call.h"
#include "nimbus/media/vdb_density.h"
#include "nimbus/os/regular_file.h"

namespace nimbus {
namespace {

namespace fs = std::filesystem;

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

enum class Format { OpenVdb, NanoVdb };

// Only a regular file that starts with either library's magic number is handed to a library: a
// directory, a FIFO or a text file is one line here, and neither reader sees it.
Format sniff(const std::string& file) {
  std::optional<RegularFile> f;
  try {
    f.emplace(file);
  } catch (const FileOpenError& e) {
    fail_file(file, e.reason);
  }
  std::istream& in = f->stream();
  unsigned char head[8] = {};
  in.read(reinterpret_cast<char*>(head), sizeof head);
  const std::streamsize got = in.gcount();
  std::uint64_t magic64 = 0;
  std::int32_t magic32 = 0;
  std::memcpy(&magic64, head, sizeof magic64);
  std::memcpy(&magic32, head, sizeof magic32);
  if (got == 8 && magic64 == NANOVDB_MAGIC_NUMBER) return Format::NanoVdb;
  if (got >= 4 && magic32 == openvdb::OPENVDB_MAGIC) return Format::OpenVdb;
  fail_file(file, "not a VDB file (it starts with neither OpenVDB's nor NanoVDB's magic number)");
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

// The limits on reading a .vdb in a child: generous for real files (their data rarely expands
// beyond 10x when decompressed, and the child holds it about four times over), small against
// the gigabytes a damaged length field asks for.
IsolationLimits reader_limits(const std::string& file) {
  std::error_code ec;
  const double bytes = double(fs::file_size(file, ec));
  return {(std::uint64_t(1) << 30) + std::uint64_t(128 * bytes), 10 + bytes / 1e6};
}

// read_openvdb in a child process (isolated_call.h): what OpenVDB does with a damaged file
// (allocations of gigabytes, crashes, warnings on stderr) stays there. The child sends back the
// cleaned grid in OpenVDB's stream format, uncompressed, or the VdbError it threw.
openvdb::FloatGrid::Ptr read_openvdb_isolated(const std::string& file, const std::string& name,
                                              const std::string& quantity) {
  const IsolationLimits limits = reader_limits(file);
  IsolatedResult r = call_isolated(
      [&]() -> std::string {
        try {
          const openvdb::FloatGrid::Ptr grid = read_openvdb(file, name, quantity);
          std::ostringstream out(std::ios::binary);
          openvdb::io::Stream stream(out);
          stream.setCompression(openvdb::io::COMPRESS_NONE);
          stream.write(openvdb::GridCPtrVec{grid});
          return "G" + std::move(out).str();
        } catch (const VdbError& e) {
          return fmt::format("E{}\n{}", e.key, e.what());
        } catch (const std::bad_alloc&) {
          throw;
        } catch (const std::exception& e) {
          return fmt::format("Efile\n{}: corrupted OpenVDB file ({})", file, e.what());
        }
      },
      limits);
  using Status = IsolatedResult::Status;
  switch (r.status) {
    case Status::NotIsolated:
      return read_openvdb(file, name, quantity);
    case Status::OutOfMemory:
      fail_file(file, fmt::format("corrupted OpenVDB file (reading it needed more than {:.1f} GB, "
                                  "the limit for a file of this size)",
                                  double(limits.memory_bytes) / 1e9));
    case Status::TimedOut:
      fail_file(file, fmt::format("corrupted OpenVDB file (reading it took more than {:.0f} s, "
                                  "the limit for a file of this size)",
                                  limits.seconds));
    case Status::Crashed:
      fail_file(file, r.signal ? fmt::format("corrupted OpenVDB file (OpenVDB's reader crashed "
                                             "on it: {})",
                                             strsignal(r.signal))
                               : "corrupted OpenVDB file (OpenVDB's reader failed on it)");
    case Status::Done:
      break;
  }
  if (!r.bytes.empty() && r.bytes[0] == 'E') {
    const std::size_t eol = r.bytes.find('\n');
    throw VdbError(r.bytes.substr(1, eol - 1), r.bytes.substr(eol + 1));
  }
  // The grid's bytes are moved, not copied, into the stream; the 'G' before them is skipped.
  std::istringstream in(std::move(r.bytes), std::ios::binary);
  in.ignore(1);
  openvdb::io::Stream stream(in, /*delayLoad=*/false);
  return openvdb::gridPtrCast<openvdb::FloatGrid>(stream.getGrids()->at(0));
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
  Mat4 m = Mat4::identity();
  for (int c = 0; c < 3; ++c) {
    openvdb::Vec3d e(0, 0, 0);
    e[c] = 1;
    const openvdb::Vec3d image = t.indexToWorld(e) - o;
    for (int r = 0; r < 3; ++r) m(r, c) = image[r];
  }
  for (int r = 0; r < 3; ++r) m(r, 3) = o[r];
  return m;
}

}  // namespace

VdbFileGrid read_vdb_file(const std::string& file, const std::string& name,
                          const std::string& quantity, bool isolate) {
  openvdb::initialize();  // registers the grid types; cheap after the first call
  const Format format = sniff(file);
  openvdb::FloatGrid::Ptr grid;
  try {
    if (format == Format::NanoVdb)
      grid = read_nanovdb(file, name, quantity);
    else if (isolate)
      grid = read_openvdb_isolated(file, name, quantity);
    else
      grid = read_openvdb(file, name, quantity);
  } catch (const VdbError&) {
    throw;
  } catch (const std::exception& e) {
    // Past the header, a library's exception means data it could not decode.
    fail_file(file, fmt::format("corrupted {} file ({})",
                                format == Format::OpenVdb ? "OpenVDB" : "NanoVDB", e.what()));
  }
  auto handle = std::make_shared<nanovdb::GridHandle<>>(
      nanovdb::openToNanoVDB(*grid, nanovdb::StatsMode::MinMax, nanovdb::ChecksumMode::Disable));
  VdbFileGrid out;
  out.grid = handle->grid<float>();
  out.owner = std::move(handle);
  out.world_from_index = world_from_index(grid->transform());
  out.active_voxels = grid->activeVoxelCount();
  return out;
}

}  // namespace nimbus
