// Polygonization (mesh/polygonize.h): quadrics mesh to their analytic volume and area; every
// vertex lies within ε of the exact surface and every surface point within 2ε of the mesh; the
// mesh is a closed 2-manifold of the shape's Euler characteristic and components; a thin
// free-form spike keeps its tip, and the mesh is the same for any thread count. A glTF binary
// file (io/mesh_file.h) read back by the spec's layout holds the mesh's own bytes and bounds.

#include "nimbus/mesh/mesh.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "nimbus/frep/intersect.h"
#include "nimbus/io/mesh_file.h"
#include "nimbus/math/constants.h"
#include "nimbus/mesh/measure.h"
#include "nimbus/mesh/polygonize.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "support/process.h"

namespace nimbus {
namespace {

// The tape of the first object of a scene whose only shape is `shape` (JSON).
Tape tape_of(const std::string& shape) {
  const std::string text =
      R"({"camera": {"from": [0, 0, 5], "to": [0, 0, 0]}, "objects": [{"shape": )" + shape +
      R"(, "surface": {"type": "diffuse"}}]})";
  return compile_scene(load_scene_text(text, "mesh_test")).objects.at(0).tape;
}

double distance_to_mesh(const TriangleMesh& m, const Vec3& p) {
  double best = kInf;
  for (const auto& t : m.triangles)
    best = std::min(
        best, point_triangle_distance(p, m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]));
  return best;
}

struct Checked {
  TriangleMesh mesh;
  MeshTopology topology;
  PolygonizeReport report;
};

// Meshes at ε and checks what holds for every shape: closed, 2-manifold, vertices within ε of
// the surface (surface_distance from the vertex along its normal), and dense surface samples
// within 2ε of the mesh.
Checked mesh_and_check(const Tape& tape, double eps, int samples = 300) {
  Checked c;
  c.mesh = polygonize(tape, {eps, 4000000}, &c.report);
  c.topology = mesh_topology(c.mesh);
  EXPECT_TRUE(c.topology.watertight);
  EXPECT_TRUE(c.topology.manifold);
  EXPECT_EQ(c.mesh.positions.size(), c.mesh.normals.size());
  double worst = 0;
  for (size_t i = 0; i < c.mesh.positions.size(); ++i)
    worst = std::max(worst, surface_distance(tape, c.mesh.positions[i], c.mesh.normals[i], 1.0));
  EXPECT_LE(worst, eps);
  EXPECT_LE(c.report.vertex_error, eps);
  double hausdorff = 0;
  for (const Vec3& p : surface_samples(tape, samples))
    hausdorff = std::max(hausdorff, distance_to_mesh(c.mesh, p));
  EXPECT_LE(hausdorff, 2 * eps);
  return c;
}

TEST(Polygonize, SphereMeetsItsVolumeAreaAndTopology) {
  const Tape tape = tape_of(R"({"type": "sphere", "center": [0.1, -0.2, 0.3], "radius": 1})");
  const Checked c = mesh_and_check(tape, 2e-3);
  EXPECT_NEAR(enclosed_volume(c.mesh), 4 * kPi / 3, 0.005 * 4 * kPi / 3);
  EXPECT_NEAR(surface_area(c.mesh), 4 * kPi, 0.005 * 4 * kPi);
  EXPECT_EQ(c.topology.euler, 2);
  EXPECT_EQ(c.topology.components, 1);
}

// The refined grid's cell is predicted from the last grid's error (error ∝ cell² on a smooth
// surface), and a grid's few failing faces are bisected, so the mesh lands near the bound rather
// than up to four times below it, as halving the cell would: fewer triangles for the same bound.
TEST(Polygonize, LandsNearTheBoundOnASmoothShape) {
  const Tape tape = tape_of(R"({"type": "sphere", "radius": 1})");
  for (const double eps : {0.004, 0.001}) {
    PolygonizeReport report;
    const TriangleMesh mesh = polygonize(tape, {eps, 0}, &report);
    EXPECT_LE(report.face_error, eps);
    EXPECT_GE(report.face_error, 0.4 * eps) << "ε " << eps << ", " << report.grids << " grids";
    // A sphere's chord error is about (cell)²/(8r) on each axis-aligned cell: triangles grow as
    // 1/ε, and stay below what the halving sequence gave (9 696 at 0.004; four times that at
    // 0.001).
    EXPECT_LT(mesh.triangles.size(), size_t(9696 * 0.004 / eps * 0.6));
  }
}

TEST(Polygonize, EllipsoidMeetsItsVolumeAndArea) {
  const Tape tape =
      tape_of(R"({"type": "ellipsoid", "center": [0, 0, 0], "radii": [1, 0.6, 0.4]})");
  const Checked c = mesh_and_check(tape, 2e-3);
  const double a = 1, b = 0.6, cc = 0.4, p = 1.6075;  // Knud Thomsen's area, within 1.061 %
  const double area =
      4 * kPi *
      std::pow((std::pow(a * b, p) + std::pow(a * cc, p) + std::pow(b * cc, p)) / 3, 1 / p);
  EXPECT_NEAR(enclosed_volume(c.mesh), 4 * kPi / 3 * a * b * cc, 0.005 * 4 * kPi / 3 * a * b * cc);
  EXPECT_NEAR(surface_area(c.mesh), area, 0.0106 * area);
  EXPECT_EQ(c.topology.euler, 2);
}

// A flat ellipsoid with a hole punched through by a negative perturbation: a ring, genus 1.
TEST(Polygonize, RingFreeFormHasEulerCharacteristicZero) {
  const Tape tape = tape_of(R"({"type": "freeform",
      "base": {"type": "ellipsoid", "radii": [1, 0.3, 1]},
      "perturbations": [{"shape": {"type": "sphere", "center": [0, 0, 0], "radius": 0.55},
                         "weight": -100}]})");
  const Checked c = mesh_and_check(tape, 2e-3);
  EXPECT_EQ(c.topology.euler, 0);
  EXPECT_EQ(c.topology.components, 1);
}

TEST(Polygonize, TwoDisjointBallsAreTwoComponents) {
  const Tape tape = tape_of(R"({"type": "union", "shapes": [
      {"type": "sphere", "center": [-0.6, 0, 0], "radius": 0.5},
      {"type": "sphere", "center": [0.7, 0.1, 0], "radius": 0.4}]})");
  const Checked c = mesh_and_check(tape, 2e-3);
  EXPECT_EQ(c.topology.components, 2);
  EXPECT_EQ(c.topology.euler, 4);
}

TEST(Polygonize, FreeFormWithFourPerturbations) {
  const Tape tape = tape_of(R"({"type": "freeform",
      "base": {"type": "ellipsoid", "radii": [0.95, 0.8, 0.8]},
      "perturbations": [
        {"shape": {"type": "sphere", "center": [0.55, 0.45, 0.3], "radius": 0.45}, "weight": 0.8},
        {"shape": {"type": "sphere", "center": [-0.6, 0.35, -0.2], "radius": 0.4}, "weight": 0.8},
        {"shape": {"type": "sphere", "center": [0.1, -0.7, 0.5], "radius": 0.5}, "weight": -0.6},
        {"shape": {"type": "sphere", "center": [0.0, 0.3, 0.75], "radius": 0.35}, "weight": 0.5}]})");
  const Checked c = mesh_and_check(tape, 2e-3);
  EXPECT_EQ(c.topology.euler, 2);
  EXPECT_EQ(c.topology.components, 1);
}

// A spike: a thin upright ellipsoid perturbing a ball. Its tip, the exact surface's highest point
// on the axis, must be in the mesh within 2ε.
// The mesh edges that lie on a sharp edge of the shape (both ends and the midpoint): their
// dihedral angles and lengths. `on_edge` says whether a point is on it.
struct MeshEdge {
  double angle, length;
};
template <class OnEdge>
std::vector<MeshEdge> sharp_edges(const TriangleMesh& m, OnEdge&& on_edge) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<Vec3>> faces;
  for (const auto& t : m.triangles) {
    const Vec3 n = normalize(
        cross(m.positions[t[1]] - m.positions[t[0]], m.positions[t[2]] - m.positions[t[0]]));
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[size_t(k)], b = t[size_t((k + 1) % 3)];
      faces[{std::min(a, b), std::max(a, b)}].push_back(n);
    }
  }
  std::vector<MeshEdge> edges;
  for (const auto& [edge, normals] : faces) {
    const Vec3 &a = m.positions[edge.first], &b = m.positions[edge.second];
    if (normals.size() == 2 && on_edge(a) && on_edge(b) && on_edge((a + b) * 0.5))
      edges.push_back({std::acos(std::clamp(dot(normals[0], normals[1]), -1.0, 1.0)) * 180 / kPi,
                       length(b - a)});
  }
  return edges;
}

// A CSG edge is kept: the mesh edges along a cylinder's rim, cut by a slab, meet at 90° within
// 5° (a curved sharp edge: issue 43).
TEST(Polygonize, CylinderCutBySlabKeepsItsRim) {
  const double eps = 0.003;
  const Tape cylinder = tape_of(R"({"type": "intersection", "shapes": [
      {"type": "cylinder", "axis": [0, 0, 1], "radius": 0.5},
      {"type": "slab", "normal": [0, 0, 1], "thickness": 1.6}]})");
  const Checked c = mesh_and_check(cylinder, eps);
  EXPECT_EQ(c.topology.euler, 2);
  // Within the area times ε of π r² h.
  EXPECT_NEAR(enclosed_volume(c.mesh), kPi * 0.25 * 1.6,
              (2 * kPi * 0.25 + 2 * kPi * 0.5 * 1.6) * eps);
  const auto on_rim = [&](const Vec3& p) {
    return std::abs(std::hypot(p.x, p.y) - 0.5) <= eps && std::abs(std::abs(p.z) - 0.8) <= eps;
  };
  const std::vector<MeshEdge> rim = sharp_edges(c.mesh, on_rim);
  EXPECT_GE(rim.size(), 16u);
  for (const MeshEdge& e : rim) EXPECT_NEAR(e.angle, 90, 5);
}

// A box turned off the grid's axes keeps its edges and corners (docs/meshes.md, step 5): a
// mesh edge that crosses a sharp edge is split on it, and a face across a corner at the corner.
// The mesh edges along the box's edges cover them, every one meets at 90° within 5°, and each
// corner is a vertex. Three turns, three bounds.
TEST(Polygonize, TurnedBoxKeepsItsEdgesAndCorners) {
  const Vec3 half{0.5, 0.4, 0.3};
  struct Turn {
    Vec3 axis;
    double degrees, eps;
  };
  for (const Turn& turn :
       {Turn{{1, 2, 3}, 25, 0.003}, Turn{{-2, 1, 0.5}, 40, 0.004}, Turn{{0, 0, 1}, 30, 0.002}}) {
    SCOPED_TRACE(turn.degrees);
    const double eps = turn.eps;
    const Vec3 axis = normalize(turn.axis);
    const Tape box = tape_of(fmt::format(
        R"({{"type": "box", "min": [-0.5, -0.4, -0.3], "max": [0.5, 0.4, 0.3],
            "transform": [{{"rotate": {{"axis": [{}, {}, {}], "degrees": {}}}}}]}})",
        turn.axis.x, turn.axis.y, turn.axis.z, turn.degrees));
    const Checked c = mesh_and_check(box, eps);
    EXPECT_EQ(c.topology.euler, 2);
    // Rodrigues' rotation by `degrees` about the axis.
    const auto rotate = [&](const Vec3& p, double degrees) {
      const double cs = std::cos(degrees * kPi / 180), sn = std::sin(degrees * kPi / 180);
      return p * cs + cross(axis, p) * sn + axis * (dot(axis, p) * (1 - cs));
    };
    // A point within a tenth of ε of two faces: on the edge, not on a face beside it.
    const double tol = 0.1 * eps;
    const auto on_edge = [&](const Vec3& p) {
      const Vec3 q = rotate(p, -turn.degrees);
      int faces = 0;
      for (int k = 0; k < 3; ++k) {
        if (std::abs(q[k]) > half[k] + tol) return false;
        faces += std::abs(std::abs(q[k]) - half[k]) <= tol;
      }
      return faces >= 2;
    };
    // A mesh edge this near the sharp edge is either on it (90°) or beside it in one face (0°,
    // both its faces in one plane); a chamfer or a turned face would be in between.
    double kept = 0;
    int off = 0;
    for (const MeshEdge& e : sharp_edges(c.mesh, on_edge)) {
      if (std::abs(e.angle - 90) <= 5)
        kept += e.length;
      else if (e.angle > 5)
        ++off;
    }
    EXPECT_GE(kept, 0.99 * 8 * (half.x + half.y + half.z));
    EXPECT_EQ(off, 0);
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 q{corner & 1 ? half.x : -half.x, corner & 2 ? half.y : -half.y,
                   corner & 4 ? half.z : -half.z};
      const Vec3 p = rotate(q, turn.degrees);
      double nearest = kInf;
      for (const Vec3& v : c.mesh.positions) nearest = std::min(nearest, length(v - p));
      EXPECT_LE(nearest, 0.01 * eps) << "corner " << corner;
    }
  }
}

TEST(Polygonize, ThinFreeFormSpikeKeepsItsTip) {
  const Tape tape = tape_of(R"({"type": "freeform",
      "base": {"type": "sphere", "center": [0, 0, 0], "radius": 0.5},
      "perturbations": [{"shape": {"type": "ellipsoid", "center": [0, 0.6, 0],
                                   "radii": [0.05, 0.6, 0.05]}, "weight": 40}]})");
  const double eps = 2e-3;
  const Checked c = mesh_and_check(tape, eps);
  const auto t = first_hit(tape, Ray{{0, 3, 0}, {0, -1, 0}}, 0, 3);
  ASSERT_TRUE(t);
  const double tip = 3 - *t;
  double top = -kInf;
  for (const Vec3& p : c.mesh.positions) top = std::max(top, p.y);
  EXPECT_GT(tip, 0.9);
  EXPECT_NEAR(top, tip, 2 * eps);
}

// A free form, and a turned box whose sharp edges and corners are split (docs/meshes.md, step 5).
TEST(Polygonize, SameMeshForAnyThreadCount) {
  for (const char* shape : {R"({"type": "freeform",
      "base": {"type": "ellipsoid", "radii": [0.9, 0.7, 0.8]},
      "perturbations": [{"shape": {"type": "sphere", "center": [0.5, 0.4, 0], "radius": 0.4},
                         "weight": 1}]})",
                            R"({"type": "box", "min": [-0.5, -0.4, -0.3], "max": [0.5, 0.4, 0.3],
      "transform": [{"rotate": {"axis": [1, 2, 3], "degrees": 25}}]})"}) {
    const Tape tape = tape_of(shape);
    TriangleMesh one, two;
    {
      tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
      one = polygonize(tape, {3e-3, 0});
    }
    {
      tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
      two = polygonize(tape, {3e-3, 0});
    }
    ASSERT_EQ(one.positions.size(), two.positions.size());
    ASSERT_EQ(one.triangles, two.triangles);
    for (size_t i = 0; i < one.positions.size(); ++i) {
      EXPECT_EQ(one.positions[i].x, two.positions[i].x);
      EXPECT_EQ(one.positions[i].y, two.positions[i].y);
      EXPECT_EQ(one.positions[i].z, two.positions[i].z);
    }
  }
}

TEST(Polygonize, RefusesABadErrorBoundAndATooFineGrid) {
  const Tape tape = tape_of(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1})");
  EXPECT_THROW(polygonize(tape, {0, 0}), PolygonizeError);
  EXPECT_THROW(polygonize(tape, {-1, 0}), PolygonizeError);
  try {
    polygonize(tape, {1e-6, 10000});
    FAIL() << "no error";
  } catch (const PolygonizeError& e) {
    EXPECT_NE(std::string(e.what()).find("limit is 10000"), std::string::npos) << e.what();
  }
}

std::uint32_t glb_u32(const std::string& bytes, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, bytes.data() + at, sizeof v);
  return v;
}

template <class T>
std::string bytes_of(const std::vector<T>& v) {
  return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

// Read back by the GLB layout of the glTF 2.0 spec alone, not by nimbus's writer: the header and
// both chunks, the JSON's scene, mesh and accessors, and each accessor's bytes against the mesh.
TEST(MeshFile, GlbHoldsTheMeshBytesAndBounds) {
  const TriangleMesh mesh = polygonize(
      tape_of(R"({"type": "ellipsoid", "center": [0.3, -1, 2], "radii": [1, 0.6, 0.4]})"),
      {1e-2, 0});
  ASSERT_FALSE(mesh.triangles.empty());
  EXPECT_EQ(mesh_format("some/Ball.GLB"), MeshFormat::Glb);
  const std::filesystem::path dir = test::fresh_test_dir("nimbus_mesh_file");
  write_mesh((dir / "ball.Glb").string(), mesh);
  EXPECT_THROW(write_mesh((dir / "empty.glb").string(), TriangleMesh{}), std::runtime_error);
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    names.push_back(e.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"ball.Glb"});  // no temporary left, no empty file
  std::ifstream in(dir / "ball.Glb", std::ios::binary);
  const std::string file{std::istreambuf_iterator<char>(in), {}};
  std::filesystem::remove_all(dir);

  ASSERT_GE(file.size(), 28u);
  EXPECT_EQ(file.substr(0, 4), "glTF");
  EXPECT_EQ(glb_u32(file, 4), 2u);
  EXPECT_EQ(glb_u32(file, 8), file.size());
  const std::uint32_t json_length = glb_u32(file, 12);
  EXPECT_EQ(file.substr(16, 4), "JSON");
  EXPECT_EQ(json_length % 4, 0u);
  const std::size_t bin_at = 20 + std::size_t(json_length);
  ASSERT_LE(bin_at + 8, file.size());
  const std::uint32_t bin_length = glb_u32(file, bin_at);
  EXPECT_EQ(file.substr(bin_at + 4, 4), std::string("BIN\0", 4));
  EXPECT_EQ(bin_length % 4, 0u);
  ASSERT_EQ(bin_at + 8 + bin_length, file.size());
  const std::string text = file.substr(20, json_length);
  const std::string bin = file.substr(bin_at + 8);
  // Padded with spaces after the closing brace, fewer than four.
  const std::size_t last = text.find_last_not_of(' ');
  ASSERT_NE(last, std::string::npos);
  EXPECT_EQ(text[last], '}');
  EXPECT_LT(text.size() - 1 - last, 4u);

  const nlohmann::json doc = nlohmann::json::parse(text);
  EXPECT_EQ(doc.at("asset").at("version"), "2.0");
  EXPECT_EQ(doc.at("asset").at("generator"), "nimbus");
  EXPECT_EQ(doc.at("scene"), 0);
  EXPECT_EQ(doc.at("scenes"), nlohmann::json::parse(R"([{"nodes": [0]}])"));
  EXPECT_EQ(doc.at("nodes"), nlohmann::json::parse(R"([{"mesh": 0}])"));
  ASSERT_EQ(doc.at("meshes").size(), 1u);
  ASSERT_EQ(doc.at("meshes").at(0).at("primitives").size(), 1u);
  const nlohmann::json& primitive = doc.at("meshes").at(0).at("primitives").at(0);
  EXPECT_EQ(primitive.at("mode"), 4);  // triangles
  ASSERT_EQ(doc.at("buffers").size(), 1u);
  const std::size_t buffer_length = doc.at("buffers").at(0).at("byteLength");
  EXPECT_LE(buffer_length, bin.size());
  EXPECT_LT(bin.size() - buffer_length, 4u);

  // An accessor's tightly packed bytes in BIN, its view and type checked on the way.
  const auto accessor_bytes = [&](const nlohmann::json& index, int component_type,
                                  const std::string& type, std::size_t count, int target) {
    const nlohmann::json& a = doc.at("accessors").at(index.get<std::size_t>());
    EXPECT_EQ(a.at("componentType"), component_type);
    EXPECT_EQ(a.at("type"), type);
    EXPECT_EQ(a.at("count"), count);
    const nlohmann::json& v = doc.at("bufferViews").at(a.at("bufferView").get<std::size_t>());
    EXPECT_EQ(v.at("buffer"), 0);
    EXPECT_EQ(v.at("target"), target);
    EXPECT_FALSE(v.contains("byteStride"));
    const std::size_t view_at = v.value("byteOffset", std::size_t{0});
    const std::size_t at = view_at + a.value("byteOffset", std::size_t{0});
    const std::size_t bytes = count * 4 * (type == "VEC3" ? 3 : 1);
    EXPECT_EQ(at % 4, 0u);
    EXPECT_LE(at + bytes, view_at + v.at("byteLength").get<std::size_t>());
    EXPECT_LE(view_at + v.at("byteLength").get<std::size_t>(), buffer_length);
    return bin.substr(at, bytes);
  };
  std::vector<float> positions, normals;
  std::array<float, 3> lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3 &p = mesh.positions[i], &n = mesh.normals[i];
    const float pf[3] = {float(p.x), float(p.y), float(p.z)};
    for (int k = 0; k < 3; ++k) {
      positions.push_back(pf[k]);
      lo[k] = std::min(lo[k], pf[k]);
      hi[k] = std::max(hi[k], pf[k]);
    }
    normals.insert(normals.end(), {float(n.x), float(n.y), float(n.z)});
  }
  const std::size_t vertices = mesh.positions.size();
  const nlohmann::json& attributes = primitive.at("attributes");
  // Compared with EXPECT_TRUE: a failure would otherwise print megabytes. The normals written
  // are the ones checked for unit length below.
  EXPECT_TRUE(accessor_bytes(attributes.at("POSITION"), 5126, "VEC3", vertices, 34962) ==
              bytes_of(positions));
  EXPECT_TRUE(accessor_bytes(attributes.at("NORMAL"), 5126, "VEC3", vertices, 34962) ==
              bytes_of(normals));
  for (std::size_t i = 0; i + 2 < normals.size(); i += 3)
    ASSERT_NEAR(std::hypot(normals[i], normals[i + 1], normals[i + 2]), 1, 1e-6) << i / 3;
  EXPECT_TRUE(accessor_bytes(primitive.at("indices"), 5125, "SCALAR", 3 * mesh.triangles.size(),
                             34963) == bytes_of(mesh.triangles));
  // POSITION's required bounds are exactly the written floats', read as doubles: no rounding
  // hides a bound off by less than a float's step.
  const nlohmann::json& position =
      doc.at("accessors").at(attributes.at("POSITION").get<std::size_t>());
  ASSERT_EQ(position.at("min").size(), 3u);
  ASSERT_EQ(position.at("max").size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(position.at("min").at(k).get<double>(), double(lo[k])) << k;
    EXPECT_EQ(position.at("max").at(k).get<double>(), double(hi[k])) << k;
  }
  EXPECT_NEAR(lo[0], -0.7, 0.02);  // the ellipsoid's own box, within 2ε
  EXPECT_NEAR(hi[2], 2.4, 0.02);
}

}  // namespace
}  // namespace nimbus
