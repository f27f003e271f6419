#include "nimbus/io/mesh_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <vector>

#include "nimbus/io/atomic_file.h"

namespace nimbus {

namespace {

static_assert(std::endian::native == std::endian::little, "the binary writers assume it");

constexpr std::size_t kObjBlock = 1 << 20;  // bytes of OBJ text written at once

// glTF 2.0's binary container: a 12-byte header, a JSON chunk describing the mesh, and a BIN
// chunk of the arrays it points into, each chunk an 8-byte header and 4-byte aligned data.
constexpr std::uint32_t kGlbMagic = 0x46546C67;  // "glTF"
constexpr std::uint32_t kGlbJson = 0x4E4F534A;   // "JSON"
constexpr std::uint32_t kGlbBin = 0x004E4942;    // "BIN\0"
constexpr std::uint32_t kGltfFloat = 5126, kGltfUnsignedInt = 5125;
constexpr std::uint32_t kGltfArrayBuffer = 34962, kGltfElementArrayBuffer = 34963;
static_assert(sizeof(decltype(TriangleMesh::triangles)::value_type) == 12,
              "GLB's indices are the triangles' bytes");

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

// Float positions, then float normals, then the indices: each a multiple of 4 bytes, so every
// view starts aligned and the BIN chunk needs no padding.
std::uint64_t glb_vertex_bytes(const TriangleMesh& m) {
  return 12 * std::uint64_t(m.positions.size());
}
std::uint64_t glb_index_bytes(const TriangleMesh& m) {
  return 12 * std::uint64_t(m.triangles.size());
}
std::uint64_t glb_bin_bytes(const TriangleMesh& m) {
  return 2 * glb_vertex_bytes(m) + glb_index_bytes(m);
}

// The JSON chunk's text, padded with spaces to 4 bytes: one scene of one node holding one mesh of
// one triangle list.
std::string glb_json(const TriangleMesh& m) {
  using nlohmann::json;
  // POSITION's bounds are required, and must be those of the floats written, not the doubles.
  std::array<float, 3> lo, hi;
  lo.fill(std::numeric_limits<float>::infinity());
  hi.fill(-std::numeric_limits<float>::infinity());
  for (const Vec3& p : m.positions) {
    const float v[3] = {float(p.x), float(p.y), float(p.z)};
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], v[k]);
      hi[k] = std::max(hi[k], v[k]);
    }
  }
  const std::uint64_t vertices = glb_vertex_bytes(m), indices = glb_index_bytes(m);
  auto view = [](std::uint64_t offset, std::uint64_t bytes, std::uint32_t target) {
    return json{{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}, {"target", target}};
  };
  const json position = {{"bufferView", 0},
                         {"componentType", kGltfFloat},
                         {"count", m.positions.size()},
                         {"type", "VEC3"},
                         {"min", json::array({lo[0], lo[1], lo[2]})},
                         {"max", json::array({hi[0], hi[1], hi[2]})}};
  const json normal = {{"bufferView", 1},
                       {"componentType", kGltfFloat},
                       {"count", m.positions.size()},
                       {"type", "VEC3"}};
  const json index = {{"bufferView", 2},
                      {"componentType", kGltfUnsignedInt},
                      {"count", 3 * m.triangles.size()},
                      {"type", "SCALAR"}};
  const json primitive = {
      {"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"indices", 2}, {"mode", 4}};
  const json doc = {
      {"asset", {{"version", "2.0"}, {"generator", "nimbus"}}},
      {"scene", 0},
      {"scenes", json::array({{{"nodes", json::array({0})}}})},
      {"nodes", json::array({{{"mesh", 0}}})},
      {"meshes", json::array({{{"primitives", json::array({primitive})}}})},
      {"buffers", json::array({{{"byteLength", glb_bin_bytes(m)}}})},
      {"bufferViews",
       json::array({view(0, vertices, kGltfArrayBuffer), view(vertices, vertices, kGltfArrayBuffer),
                    view(2 * vertices, indices, kGltfElementArrayBuffer)})},
      {"accessors", json::array({position, normal, index})}};
  std::string text = doc.dump();
  text.resize((text.size() + 3) / 4 * 4, ' ');
  return text;
}

void write_glb(std::FILE* f, const TriangleMesh& m, const std::string& json) {
  const std::uint64_t bin = glb_bin_bytes(m);
  const std::uint32_t header[3] = {kGlbMagic, 2, std::uint32_t(12 + 8 + json.size() + 8 + bin)};
  put(f, header, sizeof header);
  const std::uint32_t json_chunk[2] = {std::uint32_t(json.size()), kGlbJson};
  put(f, json_chunk, sizeof json_chunk);
  put_text(f, json);
  const std::uint32_t bin_chunk[2] = {std::uint32_t(bin), kGlbBin};
  put(f, bin_chunk, sizeof bin_chunk);
  for (const Vec3& p : m.positions) {
    const float v[3] = {float(p.x), float(p.y), float(p.z)};
    put(f, v, sizeof v);
  }
  for (const Vec3& n : m.normals) {
    const float v[3] = {float(n.x), float(n.y), float(n.z)};
    put(f, v, sizeof v);
  }
  put(f, m.triangles.data(), glb_index_bytes(m));
}

}  // namespace

std::optional<MeshFormat> mesh_format(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".ply") return MeshFormat::Ply;
  if (ext == ".obj") return MeshFormat::Obj;
  if (ext == ".stl") return MeshFormat::Stl;
  if (ext == ".glb") return MeshFormat::Glb;
  return std::nullopt;
}

void write_mesh(const std::string& path, const TriangleMesh& mesh) {
  const auto format = mesh_format(path);
  if (!format)
    throw std::runtime_error(path + ": unknown mesh format (use .ply, .obj, .stl or .glb)");
  if (*format == MeshFormat::Stl && mesh.triangles.size() > UINT32_MAX)
    throw std::runtime_error(path + ": more triangles than STL can count");
  // GLB's JSON comes first: its length decides, before anything is written, whether the file
  // fits the header's 32-bit length.
  std::string glb_text;
  if (*format == MeshFormat::Glb) {
    if (mesh.triangles.empty())
      throw std::runtime_error(path + ": an empty mesh (glTF needs at least one triangle)");
    glb_text = glb_json(mesh);
    if (12 + 8 + glb_text.size() + 8 + glb_bin_bytes(mesh) > UINT32_MAX)
      throw std::runtime_error(path + ": past the 4 GiB that a glTF binary file can hold");
  }
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
      case MeshFormat::Glb:
        write_glb(f.get(), mesh, glb_text);
        break;
    }
    if (std::fflush(f.get()) != 0) throw std::runtime_error("write failed");
  });
}

}  // namespace nimbus
