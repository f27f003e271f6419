#include "nimbus/io/mesh_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <vector>

#include "nimbus/io/atomic_file.h"

namespace nimbus {

namespace {

static_assert(std::endian::native == std::endian::little, "the binary writers assume it");

constexpr std::size_t kObjBlock = 1 << 20;  // bytes of OBJ text written at once

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

File open_for_writing(const std::string& path) {
  File f(std::fopen(path.c_str(), "wb"));
  if (!f) throw std::runtime_error("cannot open for writing");
  return f;
}

void put(std::FILE* f, const void* data, std::size_t bytes) {
  if (bytes > 0 && std::fwrite(data, 1, bytes, f) != bytes)
    throw std::runtime_error("write failed");
}

template <class T>
void put(std::FILE* f, const T& value) {
  put(f, &value, sizeof value);
}

void put_text(std::FILE* f, const std::string& s) {
  put(f, s.data(), s.size());
}

void write_ply(std::FILE* f, const TriangleMesh& m) {
  put_text(f,
           fmt::format("ply\nformat binary_little_endian 1.0\ncomment nimbus export-mesh\n"
                       "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
                       "property float nx\nproperty float ny\nproperty float nz\n"
                       "element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
                       m.positions.size(), m.triangles.size()));
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    const Vec3 &p = m.positions[i], &n = m.normals[i];
    const float v[6] = {float(p.x), float(p.y), float(p.z), float(n.x), float(n.y), float(n.z)};
    put(f, v, sizeof v);
  }
  for (const auto& t : m.triangles) {
    put(f, std::uint8_t{3});
    put(f, t.data(), sizeof t);
  }
}

void write_obj(std::FILE* f, const TriangleMesh& m) {
  // Lines go out in blocks of about a megabyte: the text is never held whole.
  fmt::memory_buffer buf;
  auto flush = [&](std::size_t above) {
    if (buf.size() < above) return;
    put(f, buf.data(), buf.size());
    buf.clear();
  };
  fmt::format_to(std::back_inserter(buf), "# nimbus export-mesh\n");
  for (const Vec3& p : m.positions) {
    fmt::format_to(std::back_inserter(buf), "v {:.9g} {:.9g} {:.9g}\n", p.x, p.y, p.z);
    flush(kObjBlock);
  }
  for (const Vec3& n : m.normals) {
    fmt::format_to(std::back_inserter(buf), "vn {:.6g} {:.6g} {:.6g}\n", n.x, n.y, n.z);
    flush(kObjBlock);
  }
  for (const auto& t : m.triangles) {  // OBJ indices start at 1
    fmt::format_to(std::back_inserter(buf), "f {0}//{0} {1}//{1} {2}//{2}\n", t[0] + 1, t[1] + 1,
                   t[2] + 1);
    flush(kObjBlock);
  }
  flush(0);
}

void write_stl(std::FILE* f, const TriangleMesh& m) {
  char header[80] = "nimbus export-mesh";
  put(f, header, sizeof header);
  put(f, std::uint32_t(m.triangles.size()));
  for (const auto& t : m.triangles) {
    const Vec3 &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
    const Vec3 n = cross(b - a, c - a);
    const Vec3 u = length(n) > 0 ? normalize(n) : Vec3{0, 0, 0};
    const float v[12] = {float(u.x), float(u.y), float(u.z), float(a.x), float(a.y), float(a.z),
                         float(b.x), float(b.y), float(b.z), float(c.x), float(c.y), float(c.z)};
    put(f, v, sizeof v);
    put(f, std::uint16_t{0});
  }
}

}  // namespace

std::optional<MeshFormat> mesh_format(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".ply") return MeshFormat::Ply;
  if (ext == ".obj") return MeshFormat::Obj;
  if (ext == ".stl") return MeshFormat::Stl;
  return std::nullopt;
}

void write_mesh(const std::string& path, const TriangleMesh& mesh) {
  const auto format = mesh_format(path);
  if (!format) throw std::runtime_error(path + ": unknown mesh format (use .ply, .obj or .stl)");
  if (*format == MeshFormat::Stl && mesh.triangles.size() > UINT32_MAX)
    throw std::runtime_error(path + ": more triangles than STL can count");
  write_atomically(path, [&](const std::string& temp) {
    File f = open_for_writing(temp);
    switch (*format) {
      case MeshFormat::Ply:
        write_ply(f.get(), mesh);
        break;
      case MeshFormat::Obj:
        write_obj(f.get(), mesh);
        break;
      case MeshFormat::Stl:
        write_stl(f.get(), mesh);
        break;
    }
    if (std::fflush(f.get()) != 0) throw std::runtime_error("write failed");
  });
}

}  // namespace nimbus
