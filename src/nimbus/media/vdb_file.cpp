#include "nimbus/media/vdb_file.h"

#include <fmt/format.h>
#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/HostBuffer.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <new>
#include <optional>

#include "nimbus/media/isolated_call.h"
#include "nimbus/media/vdb_density.h"
#include "nimbus/media/vdb_module.h"
#include "nimbus/os/regular_file.h"
#include "nimbus/os/shared_module.h"

// The reading itself, with OpenVDB, is in nimbus_openvdb.so (vdb_module_openvdb.cpp), loaded when
// the first grid is read: what stays here tells the formats apart, loads the module and runs an
// OpenVDB file's reading in a child process.

namespace nimbus {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail_file(const std::string& file, const std::string& problem) {
  throw VdbError("file", fmt::format("{}: {}", file, problem));
}

// Only a regular file that starts with either library's magic number is handed to a library: a
// directory, a FIFO or a text file is one line here, and neither reader sees it.
VdbFormat sniff(const std::string& file) {
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
  if (got == 8 && magic64 == NANOVDB_MAGIC_NUMBER) return VdbFormat::NanoVdb;
  if (got >= 4 && magic32 == kOpenVdbMagic) return VdbFormat::OpenVdb;
  fail_file(file, "not a VDB file (it starts with neither OpenVDB's nor NanoVDB's magic number)");
}

// The module, or a VdbError that names it and why it cannot be loaded (dlerror's words).
const VdbModule& module_for(const std::string& file) {
  try {
    return vdb_module();
  } catch (const ModuleLoadError& e) {
    fail_file(file, fmt::format("reading VDB files needs nimbus's OpenVDB module: {}", e.what()));
  }
}

VdbFileGrid to_file_grid(VdbReadResult&& r) {
  VdbFileGrid out;
  out.owner = std::move(r.owner);
  out.grid = r.grid;
  out.world_from_index = r.world_from_index;
  out.active_voxels = r.active_voxels;
  return out;
}

// The module's read in this process: its failures as read_vdb_file throws them.
VdbFileGrid read_here(const VdbModule& module, const VdbReadRequest& request) {
  VdbReadResult r = module.read(request);
  using Status = VdbReadResult::Status;
  if (r.status == Status::OutOfMemory && r.message.empty()) throw std::bad_alloc();
  if (r.status != Status::Done) throw VdbError(r.key, r.message);
  return to_file_grid(std::move(r));
}

// The limits on reading a .vdb in a child: generous for real files (their data rarely expands
// beyond 10x when decompressed, and the child holds it about four times over), small against
// the gigabytes a damaged length field asks for.
IsolationLimits reader_limits(const std::string& file) {
  std::error_code ec;
  const double bytes = double(fs::file_size(file, ec));
  return {(std::uint64_t(1) << 30) + std::uint64_t(128 * bytes), 10 + bytes / 1e6};
}

// What the child sends back: "G", the grid's transform (16 doubles) and active voxel count, then
// the NanoVDB grid's bytes; or "E", the VdbError's key, a newline and its message.
std::string grid_bytes(const VdbReadResult& r) {
  std::string out(1 + sizeof(double) * 16 + sizeof(std::uint64_t), 'G');
  char* at = out.data() + 1;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j, at += sizeof(double)) {
      const double v = r.world_from_index(i, j);
      std::memcpy(at, &v, sizeof v);
    }
  std::memcpy(at, &r.active_voxels, sizeof r.active_voxels);
  out.append(static_cast<const char*>(r.grid), r.grid_bytes);
  return out;
}

VdbFileGrid from_grid_bytes(const std::string& bytes) {
  VdbFileGrid out;
  const char* at = bytes.data() + 1;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j, at += sizeof(double))
      std::memcpy(&out.world_from_index(i, j), at, sizeof(double));
  std::memcpy(&out.active_voxels, at, sizeof out.active_voxels);
  at += sizeof out.active_voxels;
  const std::size_t size = bytes.size() - std::size_t(at - bytes.data());
  // A NanoVDB grid is one block of memory; HostBuffer aligns it as NanoVDB needs.
  auto buffer = std::make_shared<nanovdb::HostBuffer>(nanovdb::HostBuffer::create(size));
  std::memcpy(buffer->data(), at, size);
  out.grid = buffer->data();
  out.owner = std::move(buffer);
  return out;
}

// The module's read of an OpenVDB file in a child process (isolated_call.h): what OpenVDB does with
// a damaged file (allocations of gigabytes, crashes, warnings on stderr) stays there. The module
// is loaded here first, so that the child inherits it; the child reads, cleans and converts the
// grid and sends back the NanoVDB grid, or the VdbError it threw.
VdbFileGrid read_openvdb_isolated(const VdbModule& module, const VdbReadRequest& request) {
  const std::string& file = request.file;
  const IsolationLimits limits = reader_limits(file);
  IsolatedResult r = call_isolated(
      [&]() -> std::string {
        const VdbReadResult read = module.read(request);
        switch (read.status) {
          case VdbReadResult::Status::Done:
            return grid_bytes(read);
          case VdbReadResult::Status::OutOfMemory:
            throw std::bad_alloc();
          case VdbReadResult::Status::Failed:
            break;
        }
        return fmt::format("E{}\n{}", read.key, read.message);
      },
      limits);
  using Status = IsolatedResult::Status;
  switch (r.status) {
    case Status::NotIsolated:
      return read_here(module, request);
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
  return from_grid_bytes(r.bytes);
}

}  // namespace

VdbFileGrid read_vdb_file(const std::string& file, const std::string& name,
                          const std::string& quantity, bool isolate) {
  VdbReadRequest request{file, name, quantity, sniff(file)};
  const VdbModule& module = module_for(file);
  if (request.format == VdbFormat::OpenVdb && isolate)
    return read_openvdb_isolated(module, request);
  return read_here(module, request);
}

}  // namespace nimbus
