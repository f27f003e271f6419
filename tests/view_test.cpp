// nimbus view's parts below the web server (issue 28): the preview against closed forms, the
// session's film against render()'s bits after a camera move, reloads and a broken file keeping
// the last image, the noise figure, PNG bytes in memory, and the camera's messages; the page's
// meshes (issue 43): their binary, their error, and an edit re-meshing only what it touched.

#include <arpa/inet.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/stat.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "nimbus/io/film_image.h"
#include "nimbus/io/png.h"
#include "nimbus/mesh/polygonize.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/json_reader.h"
#include "nimbus/scene/load.h"
#include "nimbus/view/camera_body.h"
#include "nimbus/view/connection_table.h"
#include "nimbus/view/loopback.h"
#include "nimbus/view/preview.h"
#include "nimbus/view/preview_mesh.h"
#include "nimbus/view/view_session.h"
#include "support/process.h"

namespace nimbus {
namespace view_test {

namespace fs = std::filesystem;

std::string scene_text(const std::string& albedo) {
  return fmt::format(R"({{
  "film": {{"width": 16, "height": 12}},
  "camera": {{"type": "perspective", "from": [0, 1, 6], "to": [0, 0, 0], "fov": 35}},
  "integrator": {{"spp": 6, "seed": 3}},
  "lights": [{{"type": "environment", "radiance": [0.8, 0.9, 1.0]}}],
  "objects": [{{"shape": {{"type": "sphere", "center": [0, 0, 0], "radius": 1.2}},
                "surface": {{"type": "diffuse", "albedo": {}}}}}]
}})",
                     albedo);
}

// A film's image rendered by render() at the scene's spp, with overrides.
Image reference(const std::string& scene, const std::vector<std::string>& overrides) {
  RenderOptions o;
  o.threads = 2;
  return to_image(render(compile_scene(load_scene_file(scene, overrides)), o).film);
}

bool same_camera(const CameraDesc& a, const CameraDesc& b) {
  return a.from == b.from && a.to == b.to && a.up == b.up && a.fov == b.fov;
}

class Session : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_test_dir("nimbus_view");
    scene_ = (dir_ / "scene.json").string();
    write(scene_text("[0.8, 0.3, 0.2]"));
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const std::string& text) const {
    // Written beside and renamed, as editors save: the session never reads half a file.
    const std::string temp = scene_ + ".tmp";
    std::ofstream(temp) << text;
    fs::rename(temp, scene_);
  }
  ViewOptions options() const {
    ViewOptions o;
    o.scene = scene_;
    o.threads = 2;
    o.rest = 0;
    o.watch_interval = 0.02;
    return o;
  }
  fs::path dir_;
  std::string scene_;
};

auto done = [](const ViewFrame& f) { return !f.preview && f.spp == f.target_spp; };

TEST_F(Session, RefinesToTheBitsOfRenderThenFollowsTheCamera) {
  ViewSession session(options());
  ASSERT_TRUE(session.wait(done, 60));
  ViewFrame f = session.frame();
  EXPECT_EQ(f.spp, 6);
  EXPECT_EQ(f.loads, 1u);
  EXPECT_EQ(f.film_image->rgb, reference(scene_, {}).rgb);
  EXPECT_GT(f.samples_per_second, 0);
  EXPECT_GT(f.noise, 0);

  CameraDesc moved = f.camera;
  moved.from = {2, 1.5, 5};
  session.set_camera(moved);
  ASSERT_TRUE(session.wait(
      [&](const ViewFrame& g) { return same_camera(g.camera, moved) && done(g); }, 60));
  f = session.frame();
  EXPECT_EQ(f.film_image->rgb, reference(scene_, {"camera.from=[2, 1.5, 5]"}).rgb);
}

TEST_F(Session, TheFilmsImageHasTheScenesAovLayers) {
  ViewOptions o = options();
  o.overrides = {R"(film.aov=["albedo", "depth"])"};
  ViewSession session(o);
  ASSERT_TRUE(session.wait(done, 60));
  const ViewFrame f = session.frame();
  RenderOptions ro;
  ro.threads = 2;
  const SceneDesc desc = load_scene_file(scene_, o.overrides);
  const Image expected = to_image(render(compile_scene(desc), ro).film, desc.settings.aovs);
  ASSERT_EQ(f.film_image->layers.size(), 2u);
  EXPECT_EQ(f.film_image->layers[0].name, "albedo");
  EXPECT_EQ(f.film_image->layers[0].values, expected.layers[0].values);
  EXPECT_EQ(f.film_image->layers[1].values, expected.layers[1].values);
  EXPECT_EQ(f.film_image->rgb, expected.rgb);
}

// To a noise target the session refines until every block is done, then stops: the image is
// render()'s to the bit, most pixels short of the cap, and the frame says all pixels are done.
TEST_F(Session, ToANoiseTargetStopsRefiningOnceEveryBlockIsDone) {
  ViewOptions o = options();
  o.spp = 512;
  o.noise_target = 0.05;
  ViewSession session(o);
  ASSERT_TRUE(session.wait(done, 120));
  const ViewFrame f = session.frame();
  EXPECT_EQ(f.pixels_done, 1.0);
  EXPECT_EQ(f.film_image->rgb,
            reference(scene_, {"integrator.spp=512", "integrator.noise_target=0.05"}).rgb);
  EXPECT_LT(f.samples_per_second * f.elapsed, 16.0 * 12 * 512 / 2);
  // Without a target the frame has no share of pixels done.
  ViewSession plain(options());
  ASSERT_TRUE(plain.wait(done, 60));
  EXPECT_EQ(plain.frame().pixels_done, -1);
}

TEST_F(Session, ShowsAPreviewWhileTheCameraMoves) {
  ViewOptions o = options();
  o.rest = 30;  // the camera never rests in this test
  ViewSession session(o);
  CameraDesc moved = session.frame().camera;
  moved.fov = 50;
  session.set_camera(moved);
  ASSERT_TRUE(session.wait(
      [&](const ViewFrame& g) { return same_camera(g.camera, moved) && g.preview && g.image; },
      60));
  const ViewFrame f = session.frame();
  EXPECT_EQ(f.spp, 0);
  EXPECT_EQ(f.film_image, nullptr);
}

TEST_F(Session, ReloadsASavedFileAndKeepsTheLastImageOfABrokenOne) {
  ViewSession session(options());
  ASSERT_TRUE(session.wait(done, 60));
  write(scene_text("[0.2, 0.3, 0.9]") + "\n");
  ASSERT_TRUE(session.wait([](const ViewFrame& g) { return g.loads == 2 && done(g); }, 60));
  ViewFrame f = session.frame();
  EXPECT_EQ(f.film_image->rgb, reference(scene_, {}).rgb);

  const std::shared_ptr<const Image> last = f.image;
  write(R"({"camera": {"from": [0, 1, 6], "to": [0, 0, 0], "fvo": 35}})");
  ASSERT_TRUE(session.wait([](const ViewFrame& g) { return !g.error.empty(); }, 60));
  f = session.frame();
  EXPECT_EQ(f.error, scene_ + ": /camera/fvo: unknown key (did you mean \"fov\"?)");
  EXPECT_EQ(f.image, last);
  EXPECT_EQ(f.loads, 2u);

  write(scene_text("[0.5, 0.5, 0.5]"));
  ASSERT_TRUE(session.wait([](const ViewFrame& g) { return g.loads == 3 && done(g); }, 60));
  EXPECT_EQ(session.frame().error, "");
}

// Issue 44: each replacement stamps differently from the one before, even from a failed load,
// so the page shows the new reason rather than the last one.
TEST_F(Session, AFileReplacedByAFifoADirectoryOrADeviceShowsWhy) {
  ViewSession session(options());
  ASSERT_TRUE(session.wait(done, 60));
  const auto error_is = [&](const std::string& expected) {
    return session.wait([&](const ViewFrame& g) { return g.error == expected; }, 60)
               ? ::testing::AssertionSuccess()
               : ::testing::AssertionFailure() << "the page shows " << session.frame().error;
  };
  fs::remove(scene_);
  ASSERT_EQ(::mkfifo(scene_.c_str(), 0600), 0);
  EXPECT_TRUE(error_is(scene_ + ": not a regular file (a FIFO)"));
  fs::remove(scene_);
  fs::create_directory(scene_);
  EXPECT_TRUE(error_is(scene_ + ": cannot open file (is a directory)"));
  fs::remove(scene_);
  fs::create_symlink("/dev/zero", scene_);
  EXPECT_TRUE(error_is(scene_ + ": not a regular file (a character device)"));
  fs::remove(scene_);
  write(scene_text("[0.5, 0.5, 0.5]"));
  ASSERT_TRUE(session.wait([](const ViewFrame& g) { return g.loads == 2 && done(g); }, 60));
  EXPECT_EQ(session.frame().error, "");
}

TEST_F(Session, ABrokenFileAtTheStartIsTheLoadersError) {
  write("{\"camera\": ");
  try {
    ViewSession session(options());
    FAIL() << "a broken file loaded";
  } catch (const SceneError& e) {
    EXPECT_TRUE(std::string(e.what()).starts_with(scene_ + ": ")) << e.what();
  }
}

TEST(ViewNoise, IsTheRelativeRmsStandardErrorOfLuminance) {
  Film film(2, 1);
  for (double v : {1.0, 3.0}) film.add(0, Rgb(v));       // mean 2, variance of mean 1
  for (double v : {2.0, 2.0, 2.0}) film.add(1, Rgb(v));  // mean 2, variance 0
  EXPECT_NEAR(view_noise(film), std::sqrt(0.5) / 2, 1e-12);
  Film sparse(1, 1);
  sparse.add(0, Rgb(1.0));
  EXPECT_EQ(view_noise(sparse), 0);
}

TEST(Preview, ASlabOfMediumIsItsClosedForm) {
  // An orthographic view through 2 units of a constant medium under a uniform sky E: every pixel
  // sees L = E T + (1 - T) mu_s / mu_t with T = exp(-2 mu_t) (a unit light scattered, no shadows).
  const std::string text = R"({
    "film": {"width": 4, "height": 4},
    "camera": {"type": "orthographic", "from": [0, 0, 5], "to": [0, 0, 0], "width": 1},
    "lights": [{"type": "environment", "radiance": 0.5}],
    "media": {"m": {"sigma_a": [0.1, 0.2, 0.3], "sigma_s": [0.4, 0.6, 0.8], "density": {"type": "constant"}}},
    "objects": [{"shape": {"type": "box", "min": [-3, -3, -1], "max": [3, 3, 1]}, "medium": "m",
                 "surface": {"type": "none"}}]
  })";
  const Scene scene = compile_scene(load_scene_text(text, "slab"));
  PreviewOptions o;
  o.steps = 4096;
  const Image image = render_preview(scene, o);
  ASSERT_EQ(image.width, 4);
  const double mu_a[3] = {0.1, 0.2, 0.3}, mu_s[3] = {0.4, 0.6, 0.8};
  for (int p = 0; p < 16; ++p)
    for (int c = 0; c < 3; ++c) {
      const double mu_t = mu_a[c] + mu_s[c], T = std::exp(-2 * mu_t);
      // The bounds may exceed the box by a little: one step's optical depth at each end.
      EXPECT_NEAR(image.rgb[3 * size_t(p) + c], 0.5 * T + (1 - T) * mu_s[c] / mu_t, 2e-3)
          << "pixel " << p << " channel " << c;
    }
}

TEST(Preview, ADiffuseSurfaceFacingTheEyeShowsItsAlbedo) {
  const std::string text = R"({
    "film": {"width": 9, "height": 9},
    "camera": {"type": "perspective", "from": [0, 0, 6], "to": [0, 0, 0], "fov": 30},
    "lights": [{"type": "environment", "radiance": 0.25}],
    "objects": [{"shape": {"type": "sphere", "center": [0, 0, 0], "radius": 1},
                 "surface": {"type": "diffuse", "albedo": [0.7, 0.5, 0.3]}}]
  })";
  const Image image = render_preview(compile_scene(load_scene_text(text, "ball")));
  const size_t centre = 3 * (4 * 9 + 4), corner = 0;
  EXPECT_NEAR(image.rgb[centre + 0], 0.7, 1e-6);
  EXPECT_NEAR(image.rgb[centre + 2], 0.3, 1e-6);
  EXPECT_FLOAT_EQ(image.rgb[corner], 0.25f);  // the sky
  EXPECT_EQ(preview_downscale(1920, 1080, 1 << 16), 6);
  EXPECT_EQ(preview_downscale(160, 120, 1 << 16), 1);
}

// The page's mesh binary read back as meshes.js reads it (view/preview_mesh.h).
struct DecodedMeshes {
  Vec3 background;
  Box bounds;
  struct Object {
    float colour[4];
    TriangleMesh mesh;
  };
  std::vector<Object> objects;
};

DecodedMeshes decode_meshes(const std::string& bytes) {
  size_t at = 0;
  const auto u32 = [&] {
    std::uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    at += 4;
    return v;
  };
  const auto f32 = [&] {
    float v;
    std::memcpy(&v, bytes.data() + at, 4);
    at += 4;
    return double(v);
  };
  const auto vec = [&] {
    const double x = f32(), y = f32(), z = f32();
    return Vec3{x, y, z};
  };
  DecodedMeshes d;
  EXPECT_EQ(bytes.substr(0, 4), "NMSH");
  at = 4;
  EXPECT_EQ(u32(), 1u);
  const std::uint32_t count = u32();
  d.background = vec();
  d.bounds.lo = vec();
  d.bounds.hi = vec();
  for (std::uint32_t i = 0; i < count; ++i) {
    DecodedMeshes::Object o;
    for (float& c : o.colour) c = float(f32());
    const std::uint32_t vertices = u32(), triangles = u32();
    for (std::uint32_t v = 0; v < vertices; ++v) o.mesh.positions.push_back(vec());
    for (std::uint32_t v = 0; v < vertices; ++v) o.mesh.normals.push_back(vec());
    for (std::uint32_t t = 0; t < triangles; ++t) o.mesh.triangles.push_back({u32(), u32(), u32()});
    d.objects.push_back(std::move(o));
  }
  EXPECT_EQ(at, bytes.size());
  return d;
}

std::string meshes_scene(double radius, const std::string& albedo) {
  return fmt::format(R"({{
    "film": {{"width": 16, "height": 12}},
    "camera": {{"from": [0, 1, 8], "to": [0, 0, 0], "fov": 35}},
    "integrator": {{"spp": 4}},
    "lights": [{{"type": "environment", "radiance": [0.2, 0.3, 0.4]}}],
    "media": {{"fog": {{"sigma_a": 0.2, "sigma_s": [0.8, 0.3, 0.8]}}}},
    "objects": [
      {{"shape": {{"type": "sphere", "center": [-1.5, 0, 0], "radius": {}}},
        "surface": {{"type": "diffuse", "albedo": {}}}}},
      {{"shape": {{"type": "box", "min": [0.5, -1, -1], "max": [2.5, 1, 1]}},
        "surface": {{"type": "conductor", "eta": [0.2, 0.9, 1.1], "k": [3.9, 2.4, 2.2]}}}},
      {{"shape": {{"type": "ellipsoid", "center": [0, 2, 0], "radii": [1, 0.5, 0.5]}},
        "surface": {{"type": "none"}}, "medium": "fog"}}]
  }})",
                     radius, albedo);
}

TEST(PreviewMeshes, AreTheObjectsClosedWithinTheirErrorInTheirColours) {
  const Scene scene = compile_scene(load_scene_text(meshes_scene(1, "[0.7, 0.5, 0.3]"), "m"));
  PreviewMesher mesher;
  PreviewMeshStats stats;
  const DecodedMeshes d = decode_meshes(mesher.update(preview_scene(scene), &stats));
  EXPECT_EQ(stats.meshed, 3);
  EXPECT_EQ(stats.reused, 0);
  ASSERT_EQ(d.objects.size(), 3u);
  EXPECT_DOUBLE_EQ(d.background.z, double(0.4f));
  // The diffuse sphere in its albedo; the metal at its normal-incidence reflectance
  // ((η − 1)² + k²) / ((η + 1)² + k²); the medium's hull see-through, in σ_s / σ_t.
  EXPECT_FLOAT_EQ(d.objects[0].colour[0], 0.7f);
  EXPECT_FLOAT_EQ(d.objects[0].colour[3], 1.0f);
  EXPECT_NEAR(d.objects[1].colour[0], (0.64 + 3.9 * 3.9) / (1.44 + 3.9 * 3.9), 1e-6);
  EXPECT_NEAR(d.objects[2].colour[1], 0.3 / 0.5, 1e-6);
  EXPECT_LT(d.objects[2].colour[3], 1.0f);
  std::uint64_t triangles = 0;
  for (size_t i = 0; i < 3; ++i) {
    const TriangleMesh& m = d.objects[i].mesh;
    triangles += m.triangles.size();
    const MeshTopology t = mesh_topology(m);
    EXPECT_TRUE(t.manifold) << "object " << i;
    EXPECT_EQ(t.euler, 2) << "object " << i;
    // Every vertex within the preview's error of the surface: 1/256 of the object's size, the
    // floats' rounding aside (exact distances for the sphere; the bounds for the others).
    const Box& b = scene.objects[i].bounds;
    const Vec3 e = b.extent();
    const double eps = std::max({e.x, e.y, e.z}) / 256 + 1e-5;
    for (const Vec3& p : m.positions) {
      if (i == 0) {
        EXPECT_LE(std::abs(length(p - Vec3{-1.5, 0, 0}) - 1), eps);
      }
      for (int k = 0; k < 3; ++k) {
        EXPECT_GE(p[k], b.lo[k] - eps);
        EXPECT_LE(p[k], b.hi[k] + eps);
      }
    }
  }
  EXPECT_EQ(stats.triangles, triangles);
  EXPECT_NEAR(d.bounds.lo.x, -2.5, 0.01);
  EXPECT_NEAR(d.bounds.hi.y, 2.5, 0.01);
}

TEST(PreviewMeshes, AnEditReMeshesOnlyTheObjectsItChanged) {
  PreviewMesher mesher;
  PreviewMeshStats stats;
  const auto meshes = [&](double radius, const std::string& albedo) {
    return decode_meshes(mesher.update(
        preview_scene(compile_scene(load_scene_text(meshes_scene(radius, albedo), "m"))), &stats));
  };
  const DecodedMeshes first = meshes(1, "0.5");
  // A colour is no reason to mesh again.
  const DecodedMeshes recoloured = meshes(1, "[0.1, 0.9, 0.1]");
  EXPECT_EQ(stats.meshed, 0);
  EXPECT_EQ(stats.reused, 3);
  EXPECT_FLOAT_EQ(recoloured.objects[0].colour[1], 0.9f);
  EXPECT_EQ(recoloured.objects[0].mesh.positions, first.objects[0].mesh.positions);
  // A new radius is: that sphere alone.
  const DecodedMeshes grown = meshes(1.2, "0.5");
  EXPECT_EQ(stats.meshed, 1);
  EXPECT_EQ(stats.reused, 2);
  EXPECT_NE(grown.objects[0].mesh.positions, first.objects[0].mesh.positions);
  EXPECT_EQ(grown.objects[1].mesh.positions, first.objects[1].mesh.positions);
  // Within the area times the preview's error (1/256 of the diameter) of the ball's volume.
  const double r = 1.2;
  EXPECT_NEAR(enclosed_volume(grown.objects[0].mesh), 4 * std::numbers::pi * r * r * r / 3,
              4 * std::numbers::pi * r * r * (2 * r / 256));
}

TEST(PreviewMeshes, StopAtTheBudgetOfTriangles) {
  const Scene scene = compile_scene(load_scene_text(meshes_scene(1, "0.5"), "m"));
  PreviewMeshOptions o;
  o.max_triangles = 100;
  PreviewMesher mesher(o);
  PreviewMeshStats stats;
  // On one thread the objects are meshed in order: the first passes the budget.
  tbb::task_arena one(1);
  const DecodedMeshes d =
      one.execute([&] { return decode_meshes(mesher.update(preview_scene(scene), &stats)); });
  EXPECT_EQ(stats.meshed, 1);
  EXPECT_EQ(stats.skipped, 2);
  ASSERT_EQ(d.objects.size(), 1u);
  EXPECT_GT(d.objects[0].mesh.triangles.size(), 100u);
}

TEST_F(Session, MeshesEachSceneItLoads) {
  write(meshes_scene(1, "0.5"));
  ViewSession session(options());
  ASSERT_TRUE(session.wait([](const ViewFrame& f) { return f.mesh_version == 1; }, 60));
  EXPECT_EQ(session.frame().mesh_stats.meshed, 3);
  EXPECT_EQ(decode_meshes(*session.frame().meshes).objects.size(), 3u);
  write(meshes_scene(0.8, "0.5"));
  ASSERT_TRUE(session.wait([](const ViewFrame& f) { return f.mesh_version == 2; }, 60));
  EXPECT_EQ(session.frame().mesh_stats.meshed, 1);
  EXPECT_EQ(session.frame().mesh_stats.reused, 2);

  ViewOptions none = options();
  none.mesh_error = 0;
  ViewSession without(none);
  ASSERT_TRUE(without.wait(done, 60));
  EXPECT_EQ(without.frame().meshes, nullptr);
}

TEST(EncodePng, IsTheBytesWritePngWrites) {
  Image image{
      3, 2, {0, 0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f, 0.8f, 0.9f, 1, 2, 0, 0, 0, 1, 1, 1}};
  const fs::path dir = test::fresh_test_dir("nimbus_png");
  const std::string path = (dir / "a.png").string();
  write_png(path, image);
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  EXPECT_EQ(encode_png(image), bytes.str());
  fs::remove_all(dir);
  EXPECT_THROW(encode_png(Image{2, 2, {0}}), std::runtime_error);
}

TEST(LoadCameraJson, ChecksAsTheSceneFileDoes) {
  const CameraDesc c =
      load_camera_json(nlohmann::json::parse(R"({"from": [1, 2, 3], "to": [0, 0, 0]})"), "camera");
  EXPECT_EQ(c.from, (Vec3{1, 2, 3}));
  EXPECT_EQ(c.fov, 40);
  auto message = [](const char* json) {
    try {
      load_camera_json(nlohmann::json::parse(json), "camera");
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(R"({"from": [0, 0, 1], "to": [0, 0, 1]})"),
            R"(camera: /camera/to: must differ from "from")");
  EXPECT_EQ(message(R"({"from": [0, 0, 1], "to": [0, 0, 0], "fov": 180})"),
            "camera: /camera/fov: must be in (0, 180)");
  EXPECT_EQ(message(R"([1, 2])"), "camera: /camera: expected an object, not an array");
}

std::string camera_body_error(std::string_view body) {
  try {
    parse_camera_body(body);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "no error";
}

// Issue 44: the camera a page posts is read as a scene file is, with its messages.
TEST(ParseCameraBody, ReadsTheBodyAsASceneFileIsRead) {
  EXPECT_EQ(parse_camera_body(R"({"from": [1, 2, 3], "to": [0, 0, 0]})").from, (Vec3{1, 2, 3}));
  EXPECT_EQ(camera_body_error(R"({"from": [0, 0, 1e999], "to": [0, 0, 0]})"),
            "camera: /from/2: the number 1e999 is beyond a double's range (finite, at most "
            "1.8e308 in magnitude)");
  EXPECT_EQ(camera_body_error(R"({"from": [0, 0, 1], "from": [0, 0, 2], "to": [0, 0, 0]})"),
            R"(camera: /from: duplicate key "from")");
  const std::string deep = camera_body_error(std::string(5000, '[') + std::string(5000, ']'));
  EXPECT_TRUE(deep.starts_with("camera: /0/0/0")) << deep;
  EXPECT_TRUE(deep.ends_with(fmt::format("nest deeper than {} levels", kMaxJsonDepth))) << deep;
  EXPECT_EQ(camera_body_error("{\"from\": \"\xff\"}"), "camera: not UTF-8 text (byte 10)");
  EXPECT_EQ(camera_body_error(R"({"from": [0, 0, 1], "to": [0, 0, 1]})"),
            R"(camera: /camera/to: must differ from "from")");
  EXPECT_TRUE(camera_body_error("{not json").starts_with("camera: parse error at line 1"));
}

using Clock = ConnectionTable::Clock;

TEST(ConnectionTable, ANewcomerPastTheLimitDropsTheStalestWaitingConnection) {
  ConnectionTable::Limits limits;
  limits.total = 3;
  limits.per_client = 2;
  ConnectionTable table(limits);
  const Clock::time_point t0{};
  const auto s = std::chrono::seconds(1);
  EXPECT_TRUE(table.add(10, "a", t0).empty());
  EXPECT_TRUE(table.add(11, "a", t0 + s).empty());
  table.answering(10, t0 + 2 * s);  // 10 is being answered: 11 is the stalest waiting one
  EXPECT_EQ(table.add(12, "a", t0 + 2 * s), std::vector<int>{11});
  EXPECT_TRUE(table.add(20, "b", t0 + 2 * s).empty());
  // Three open (10, 12, 20): a fourth from another address drops the stalest of all.
  EXPECT_EQ(table.add(30, "c", t0 + 3 * s), std::vector<int>{12});
  EXPECT_EQ(table.open(), 3u);
  // Every other one of "a" being answered: the newcomer is the one dropped.
  table.answering(30, t0 + 3 * s);
  table.answering(20, t0 + 3 * s);
  EXPECT_EQ(table.add(13, "a", t0 + 3 * s), std::vector<int>{13});
  table.remove(11);
  table.remove(12);
  table.remove(13);
  EXPECT_EQ(table.open(), 3u);
}

TEST(ConnectionTable, AWholeRequestHasADeadlineAndSoHasItsAnswer) {
  ConnectionTable::Limits limits;
  limits.request = std::chrono::seconds(5);
  limits.answer = std::chrono::seconds(3);
  ConnectionTable table(limits);
  const Clock::time_point t0{};
  const auto s = std::chrono::seconds(1);
  table.add(1, "a", t0);
  table.add(2, "a", t0 + s);
  EXPECT_EQ(table.next_deadline(), t0 + 5 * s);
  EXPECT_TRUE(table.expired(t0 + 4 * s).empty());
  table.answering(2, t0 + 4 * s);  // its request came: 3 s to take the answer
  EXPECT_EQ(table.expired(t0 + 5 * s), std::vector<int>{1});
  EXPECT_TRUE(table.expired(t0 + 6 * s).empty());  // each one once
  EXPECT_EQ(table.expired(t0 + 7 * s), std::vector<int>{2});
  table.add(3, "a", t0 + 7 * s);
  table.answering(3, t0 + 8 * s);
  table.answered(3, t0 + 9 * s);  // the next request has 5 s from the last answer
  EXPECT_TRUE(table.expired(t0 + 13 * s).empty());
  EXPECT_EQ(table.expired(t0 + 14 * s), std::vector<int>{3});
  EXPECT_EQ(table.next_deadline(), Clock::time_point::max());
}

TEST(Loopback, AddressesAndHostHeaders) {
  const auto v4 = [](const char* text) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    inet_pton(AF_INET, text, &a.sin_addr);
    return is_loopback(reinterpret_cast<const sockaddr*>(&a));
  };
  const auto v6 = [](const char* text) {
    sockaddr_in6 a{};
    a.sin6_family = AF_INET6;
    inet_pton(AF_INET6, text, &a.sin6_addr);
    return is_loopback(reinterpret_cast<const sockaddr*>(&a));
  };
  EXPECT_TRUE(v4("127.0.0.1"));
  EXPECT_TRUE(v4("127.0.0.2"));
  EXPECT_TRUE(v4("127.255.0.9"));
  EXPECT_FALSE(v4("0.0.0.0"));
  EXPECT_FALSE(v4("10.0.0.1"));
  EXPECT_FALSE(v4("128.0.0.1"));
  EXPECT_TRUE(v6("::1"));
  EXPECT_TRUE(v6("::ffff:127.0.0.3"));
  EXPECT_FALSE(v6("::"));
  EXPECT_FALSE(v6("::ffff:10.0.0.1"));

  for (const char* host : {"127.0.0.2:8080", "127.0.0.1", "localhost:8080", "LOCALHOST",
                           "[::1]:8080", "[::1]", "[::ffff:127.0.0.1]:8080"})
    EXPECT_TRUE(loopback_host_header(host, 8080)) << host;
  for (const char* host :
       {"127.0.0.2:8081", "evil.example:8080", "evil.example", "", "127.0.0.1.evil.example", "::1",
        "[::2]:8080", "10.0.0.1:8080", "127.1:8080", "localhost:", "localhost:08080"})
    EXPECT_FALSE(loopback_host_header(host, 8080)) << host;
}

}  // namespace view_test
}  // namespace nimbus
