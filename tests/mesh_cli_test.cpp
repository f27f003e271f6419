// `nimbus export-mesh` (issue 43), run as a program: PLY, OBJ, STL and glTF binary files of one
// mesh agree, the objects keep their transforms and instances, and bad input exits 2 with one
// line and writes nothing.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "nimbus/mesh/mesh.h"
#include "support/process.h"

namespace mesh_cli_test {

namespace fs = std::filesystem;
using nimbus::test::fresh_test_dir;
using nimbus::test::Ran;
using nimbus::test::run_in;

class MeshCli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = fresh_test_dir("nimbus_mesh_cli"); }
  void TearDown() override { fs::remove_all(dir_); }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }
  void write(const std::string& name, const std::string& text) {
    std::ofstream(file(name)) << text;
  }
  Ran run(const std::string& args) { return run_in(dir_, "'" NIMBUS_BINARY "' " + args); }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir_)) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }
  fs::path dir_;
};

// A ball moved by its shape's transform, and a smaller ball with two instances.
constexpr const char* kScene = R"({
  "camera": {"from": [0, 0, 8], "to": [0, 0, 0]},
  "shapes": {"ball": {"type": "sphere", "radius": 0.5, "transform": [{"translate": [3, 0, 0]}]},
             "pebble": {"type": "sphere", "radius": 0.25}},
  "objects": [{"shape": "ball", "surface": {"type": "diffuse"}},
              {"shape": "pebble", "surface": {"type": "diffuse"},
               "instances": [[{"translate": [0, 2, 0]}], [{"translate": [0, -2, 0]}]]}]})";

// A binary little-endian PLY as nimbus writes it.
nimbus::TriangleMesh read_ply(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::size_t vertices = 0, faces = 0;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream s(line);
    std::string a, b;
    s >> a >> b;
    if (a == "element" && b == "vertex") s >> vertices;
    if (a == "element" && b == "face") s >> faces;
  }
  nimbus::TriangleMesh m;
  for (std::size_t i = 0; i < vertices; ++i) {
    float v[6];
    in.read(reinterpret_cast<char*>(v), sizeof v);
    m.positions.push_back({v[0], v[1], v[2]});
    m.normals.push_back({v[3], v[4], v[5]});
  }
  for (std::size_t i = 0; i < faces; ++i) {
    std::uint8_t n = 0;
    std::array<std::uint32_t, 3> t{};
    in.read(reinterpret_cast<char*>(&n), 1);
    in.read(reinterpret_cast<char*>(t.data()), sizeof t);
    EXPECT_EQ(n, 3);
    m.triangles.push_back(t);
  }
  EXPECT_TRUE(in.good());
  return m;
}

TEST_F(MeshCli, FourFormatsOfOneClosedMeshWithTransformsAndInstances) {
  write("scene.json", kScene);
  for (const char* out : {"out.ply", "out.obj", "out.stl", "out.glb"}) {
    const Ran r = run(std::string("export-mesh scene.json --error 0.002 -q -o ") + out);
    ASSERT_EQ(r.code, 0) << r.err;
  }
  const nimbus::TriangleMesh m = read_ply(file("out.ply"));
  const nimbus::MeshTopology top = nimbus::mesh_topology(m);
  EXPECT_TRUE(top.watertight);
  EXPECT_TRUE(top.manifold);
  EXPECT_EQ(top.components, 3);
  EXPECT_EQ(top.euler, 6);
  // Each ball where its transform or instance puts it: the vertices' mean per component.
  double x_max = -1e9, y_max = -1e9, y_min = 1e9;
  for (const nimbus::Vec3& p : m.positions) {
    x_max = std::max(x_max, p.x);
    y_max = std::max(y_max, p.y);
    y_min = std::min(y_min, p.y);
  }
  EXPECT_NEAR(x_max, 3.5, 0.004);
  EXPECT_NEAR(y_max, 2.25, 0.004);
  EXPECT_NEAR(y_min, -2.25, 0.004);
  // The OBJ lists as many vertices, normals and faces; the STL counts the same triangles.
  std::ifstream obj(file("out.obj"));
  std::size_t v = 0, vn = 0, f = 0;
  std::string line;
  while (std::getline(obj, line)) {
    v += line.rfind("v ", 0) == 0;
    vn += line.rfind("vn ", 0) == 0;
    f += line.rfind("f ", 0) == 0;
  }
  EXPECT_EQ(v, m.positions.size());
  EXPECT_EQ(vn, m.positions.size());
  EXPECT_EQ(f, m.triangles.size());
  std::ifstream stl(file("out.stl"), std::ios::binary);
  char header[80];
  std::uint32_t count = 0;
  stl.read(header, 80);
  stl.read(reinterpret_cast<char*>(&count), 4);
  EXPECT_EQ(count, m.triangles.size());
  EXPECT_EQ(fs::file_size(file("out.stl")), 84 + 50 * std::uintmax_t(count));
  // The GLB's accessors count the PLY's vertices and indices, and its BIN chunk ends with the
  // PLY's triangles (mesh_test.cpp reads the whole layout).
  std::ifstream glb_in(file("out.glb"), std::ios::binary);
  const std::string glb{std::istreambuf_iterator<char>(glb_in), {}};
  ASSERT_GE(glb.size(), 28u);
  std::uint32_t glb_header[5];
  std::memcpy(glb_header, glb.data(), sizeof glb_header);
  EXPECT_EQ(glb.substr(0, 4), "glTF");
  EXPECT_EQ(glb_header[2], glb.size());
  const nlohmann::json doc = nlohmann::json::parse(glb.substr(20, glb_header[3]));
  const nlohmann::json& primitive = doc["meshes"][0]["primitives"][0];
  const auto count_of = [&](const nlohmann::json& accessor) {
    return doc["accessors"][accessor.get<std::size_t>()]["count"].get<std::size_t>();
  };
  EXPECT_EQ(count_of(primitive["attributes"]["POSITION"]), m.positions.size());
  EXPECT_EQ(count_of(primitive["attributes"]["NORMAL"]), m.positions.size());
  EXPECT_EQ(count_of(primitive["indices"]), 3 * m.triangles.size());
  const std::size_t index_bytes = m.triangles.size() * sizeof m.triangles[0];
  ASSERT_GE(glb.size(), index_bytes);
  EXPECT_EQ(std::memcmp(glb.data() + glb.size() - index_bytes, m.triangles.data(), index_bytes), 0);
  // The same bytes on one thread.
  ASSERT_EQ(run("export-mesh scene.json --error 0.002 --threads 1 -q -o one.ply").code, 0);
  std::ifstream a(file("out.ply"), std::ios::binary), b(file("one.ply"), std::ios::binary);
  EXPECT_TRUE(
      std::equal(std::istreambuf_iterator<char>(a), {}, std::istreambuf_iterator<char>(b), {}));
  // --object 1 meshes the pebble's two instances alone.
  ASSERT_EQ(run("export-mesh scene.json --object 1 --error 0.002 -q -o pebbles.ply").code, 0);
  EXPECT_EQ(nimbus::mesh_topology(read_ply(file("pebbles.ply"))).components, 2);
}

TEST_F(MeshCli, BadInputIsOneLineAndWritesNothing) {
  write("scene.json", kScene);
  write("empty.json", R"({"camera": {"from": [0, 0, 8], "to": [0, 0, 0]},
    "objects": [{"shape": {"type": "intersection", "shapes": [
      {"type": "sphere", "center": [-2, 0, 0], "radius": 0.5},
      {"type": "sphere", "center": [2, 0, 0], "radius": 0.5}]}, "surface": {"type": "diffuse"}}]})");
  const std::vector<std::string> before = names();
  const struct {
    std::string args, says;
  } cases[] = {
      {"scene.json --error 0 -o out.ply", "--error: must be > 0, not 0"},
      {"scene.json --error -1 -o out.ply", "must be > 0"},
      {"scene.json --error 0.01 -o out.gltf",
       "out.gltf: unknown mesh format (use .ply, .obj, .stl or .glb)"},
      {"scene.json --error 0.01 --object 5 -o out.ply", "--object 5: the scene has 2 objects"},
      {"missing.json --error 0.01 -o out.ply", "missing.json"},
      {"empty.json --error 0.01 -o out.ply", "no object to mesh"},
      {"scene.json --error 1e-9 -o out.ply", "limit is"},
      {"scene.json --error 0.002 --max-memory 64K -o out.ply",
       "/objects/0: an error bound of 0.002"},
      {"scene.json --error 0.002 --max-memory lots -o out.ply", "--max-memory: "},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    const Ran r = run("export-mesh " + c.args);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(names(), before);
  }
  // An output that is the scene file itself.
  fs::copy_file(file("scene.json"), file("scene.ply"));
  const Ran r = run("export-mesh scene.ply --error 0.01 -o scene.ply");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("is the scene file"), std::string::npos) << r.err;
  std::ifstream in(file("scene.ply"));
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), kScene);
}

}  // namespace mesh_cli_test
