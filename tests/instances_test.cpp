// Objects with instances (docs/scene-format.md, "instances"): a shape compiled once and placed by
// many transforms, from the scene file or from a .npy side file. Placing copies gives the
// objects that writing each copy out would, its problems are one line, and the render's
// fingerprint and memory estimate count the copies.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "nimbus/frep/bounds.h"
#include "nimbus/frep/tape.h"
#include "nimbus/io/film_image.h"
#include "nimbus/job/render_job.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/instances_file.h"
#include "nimbus/scene/load.h"

namespace nimbus {
namespace instances_test {

namespace fs = std::filesystem;

// A .npy file as numpy.save writes it (version 1): `descr` e.g. "<f8", the shape as Python
// writes it, e.g. "(2, 3, 4)", and the raw data.
void write_npy(const fs::path& path, const std::string& descr, const std::string& shape,
               const std::string& data, const std::string& fortran = "False") {
  std::string header =
      "{'descr': '" + descr + "', 'fortran_order': " + fortran + ", 'shape': " + shape + ", }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::ofstream out(path, std::ios::binary);
  out.write("\x93NUMPY\x01\x00", 8);
  const unsigned char len[2] = {static_cast<unsigned char>(header.size() & 0xff),
                                static_cast<unsigned char>(header.size() >> 8)};
  out.write(reinterpret_cast<const char*>(len), 2);
  out << header << data;
}

template <class T>
std::string bytes_of(const std::vector<T>& values) {
  std::string s(values.size() * sizeof(T), '\0');
  std::memcpy(s.data(), values.data(), s.size());
  return s;
}

// The top three rows of a translation by t after a uniform scale by k.
std::vector<double> scale_translate(double k, double x, double y, double z) {
  return {k, 0, 0, x, 0, k, 0, y, 0, 0, k, z};
}

// `n` small copies in a row along x, as (n, 3, 4) rows.
void write_row(const fs::path& path, int n) {
  std::vector<double> rows;
  for (int i = 0; i < n; ++i) {
    const std::vector<double> m = scale_translate(0.01, 0.01 * i, 0, 0);
    rows.insert(rows.end(), m.begin(), m.end());
  }
  write_npy(path, "<f8", "(" + std::to_string(n) + ", 3, 4)", bytes_of(rows));
}

class Instances : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("nimbus_instances_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A scene of a floor and `objects` (a JSON list), its named shapes "ball" (a sphere) and
  // "rock" (a free form of four perturbations), written to scene.json.
  std::string scene_file(const std::string& objects) const {
    const std::string text = R"({
      "film": {"width": 24, "height": 16}, "integrator": {"spp": 2, "max_depth": 3},
      "camera": {"from": [0, 4, 6], "to": [0, 0, 0], "fov": 50},
      "lights": [{"type": "directional", "direction": [-0.3, -1, -0.4], "irradiance": 2},
                 {"type": "environment", "radiance": 0.3}],
      "shapes": {
        "ball": {"type": "sphere", "radius": 1},
        "rock": {"type": "freeform", "base": {"type": "sphere", "radius": 1}, "perturbations": [
          {"shape": {"type": "sphere", "center": [0.8, 0.3, 0], "radius": 0.5}, "weight": 2},
          {"shape": {"type": "sphere", "center": [-0.5, 0.6, 0.4], "radius": 0.5}, "weight": -3},
          {"shape": {"type": "sphere", "center": [0.1, -0.7, 0.6], "radius": 0.5}, "weight": 2},
          {"shape": {"type": "sphere", "center": [0, 0.2, -0.9], "radius": 0.5}, "weight": -2}]}},
      "objects": [{"shape": {"type": "box", "min": [-4, -1, -4], "max": [4, 0, 4]}},)" +
                             objects + "]}";
    const fs::path path = dir_ / "scene.json";
    std::ofstream(path) << text;
    return path.string();
  }

  // The message of loading (and compiling) the scene of `objects`.
  std::string error(const std::string& objects) const {
    try {
      compile_scene(load_scene_file(scene_file(objects)));
    } catch (const SceneError& e) {
      return e.what();
    }
    return "(no error)";
  }

  fs::path dir_;
};

// The copies of a grid of spheres and of free forms, from a .npy file and from an inline list,
// render the image that the same objects written out one by one render, to the bit (for a
// sphere the placed bounds are the compiled ones; the free forms' bounds come from the shape's
// own, which the first hits do not depend on).
TEST_F(Instances, CopiesRenderAsTheObjectsWrittenOut) {
  std::vector<double> rows;
  std::string inline_list = "[", written_out;
  for (int i = 0; i < 9; ++i) {
    const double x = -2 + 2 * (i % 3), z = -2 + 2 * (i / 3), k = 0.3 + 0.05 * i;
    const std::vector<double> m = scale_translate(k, x, k, z);
    rows.insert(rows.end(), m.begin(), m.end());
    const std::string t = "[{\"scale\": " + std::to_string(k) + "}, {\"translate\": [" +
                          std::to_string(x) + ", " + std::to_string(k) + ", " + std::to_string(z) +
                          "]}]";
    inline_list += (i ? ", " : "") + t;
    written_out += std::string(i ? ", " : "") +
                   R"({"shape": {"type": "union", "shapes": ["SHAPE"], "transform": )" + t + "}}";
  }
  inline_list += "]";
  // The inline list's decimal text is what the file holds too.
  for (double& v : rows) v = std::stod(std::to_string(v));
  write_npy(dir_ / "grid.npy", "<f8", "(9, 3, 4)", bytes_of(rows));
  for (const std::string shape : {"ball", "rock"}) {
    SCOPED_TRACE(shape);
    const auto render_image = [&](std::string objects) {
      for (size_t at; (at = objects.find("SHAPE")) != std::string::npos;)
        objects.replace(at, 5, shape);
      const Scene scene = compile_scene(load_scene_file(scene_file(objects)));
      EXPECT_EQ(scene.objects.size(), 10u);
      return to_image(render(scene).film).rgb;
    };
    const auto reference = render_image(written_out);
    EXPECT_EQ(render_image(R"({"shape": "SHAPE", "instances": {"file": "grid.npy"}})"), reference);
    EXPECT_EQ(render_image(R"({"shape": "SHAPE", "instances": )" + inline_list + "}"), reference);
  }
}

// A placed tape is the tape of the shape wrapped in the placement, coefficient for coefficient;
// its bounds enclose the searched ones (for a rotation too) and, for a translation and scale,
// are as tight up to the search's resolution.
TEST_F(Instances, PlacedTapesAreTheWrappedShapesWithEnclosingBounds) {
  const SceneDesc desc = load_scene_file(scene_file(R"({"shape": "rock"})"));
  const ShapeDesc& rock = *desc.objects[1].shape;
  const Tape local = compile(rock, FUse::Sign);
  for (const Mat4& m : {Mat4::translate({3, -1, 2}) * Mat4::scale({0.5, 0.5, 0.5}),
                        Mat4::rotate({1, 2, 3}, 37) * Mat4::scale({2, 1, 1})}) {
    const Tape placed = compile_placed(rock, m, FUse::Sign, local.bounds);
    const Tape wrapped = compile(*with_transform(desc.objects[1].shape, m), FUse::Sign);
    ASSERT_EQ(placed.quadrics.size(), wrapped.quadrics.size());
    for (size_t q = 0; q < placed.quadrics.size(); ++q)
      EXPECT_EQ(placed.quadrics[q].a, wrapped.quadrics[q].a);
    ASSERT_EQ(placed.code.size(), wrapped.code.size());
    EXPECT_EQ(placed.kind, wrapped.kind);
    const Box &a = placed.bounds.box, &b = wrapped.bounds.box;
    for (int k = 0; k < 3; ++k) {
      EXPECT_LE(a.lo[k], b.lo[k]);
      EXPECT_GE(a.hi[k], b.hi[k]);
    }
    // Points of the placed shape lie in its bounds (a 24³ lattice over a box around both).
    const Box around = unite(a, b);
    int inside = 0;
    for (int i = 0; i < 24 * 24 * 24; ++i) {
      const Vec3 t{(i % 24 + 0.5) / 24, (i / 24 % 24 + 0.5) / 24, (i / 576 + 0.5) / 24};
      const Vec3 e = around.extent();
      const Vec3 p = around.lo + Vec3{e.x * t.x, e.y * t.y, e.z * t.z};
      if (evaluate(placed, p) <= 0) continue;
      ++inside;
      for (int k = 0; k < 3; ++k) EXPECT_TRUE(p[k] >= a.lo[k] && p[k] <= a.hi[k]);
    }
    EXPECT_GT(inside, 100);
  }
  // A translation and a scale carry the search's bounds: within a 128th of the shape's size.
  const Mat4 m = Mat4::translate({3, -1, 2}) * Mat4::scale({0.5, 0.5, 0.5});
  const Box a = compile_placed(rock, m, FUse::Sign, local.bounds).bounds.box;
  const Box b = compile(*with_transform(desc.objects[1].shape, m), FUse::Sign).bounds.box;
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(a.lo[k], b.lo[k], b.extent()[k] / 64);
    EXPECT_NEAR(a.hi[k], b.hi[k], b.extent()[k] / 64);
  }
}

// Translations (N, 3) and full matrices (N, 4, 4) of float32 read as (N, 3, 4) rows do.
TEST_F(Instances, FilesHoldTranslationsRowsOrMatricesInEitherPrecision) {
  write_npy(dir_ / "t.npy", "<f4", "(2, 3)", bytes_of(std::vector<float>{1, 2, 3, -4, 5, 0.5f}));
  const std::vector<Mat4> t = read_instances_file((dir_ / "t.npy").string());
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(transform_point(t[1], {0, 0, 0}), (Vec3{-4, 5, 0.5}));
  EXPECT_EQ(transform_point(t[0], {1, 1, 1}), (Vec3{2, 3, 4}));
  std::vector<double> m = scale_translate(2, 1, 0, 0);
  m.insert(m.end(), {0, 0, 0, 1});
  write_npy(dir_ / "m.npy", "<f8", "(1, 4, 4)", bytes_of(m));
  const std::vector<Mat4> r = read_instances_file((dir_ / "m.npy").string());
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(transform_point(r[0], {1, 1, 1}), (Vec3{3, 2, 2}));
}

// Every problem with instances is one line naming the key (and the file and instance).
TEST_F(Instances, BadInstancesAreOneLineNamingThePlace) {
  const std::string good = bytes_of(scale_translate(1, 0, 0, 0));
  write_npy(dir_ / "shape.npy", "<f8", "(3, 4)", good);
  write_npy(dir_ / "big.npy", ">f8", "(1, 3, 4)", good);
  write_npy(dir_ / "ints.npy", "<i8", "(1, 3, 4)", good);
  write_npy(dir_ / "fortran.npy", "<f8", "(1, 3, 4)", good, "True");
  write_npy(dir_ / "short.npy", "<f8", "(2, 3, 4)", good);
  write_npy(dir_ / "none.npy", "<f8", "(0, 3, 4)", "");
  write_npy(dir_ / "huge.npy", "<f8", "(100000000000, 3)", good);
  std::vector<double> nan = scale_translate(1, 0, 0, 0);
  nan[3] = std::numeric_limits<double>::quiet_NaN();
  write_npy(dir_ / "nan.npy", "<f8", "(1, 3, 4)", bytes_of(nan));
  std::vector<double> flat = scale_translate(1, 0, 0, 0);
  const std::vector<double> zero = scale_translate(0, 0, 0, 0);
  flat.insert(flat.end(), zero.begin(), zero.end());
  write_npy(dir_ / "flat.npy", "<f8", "(2, 3, 4)", bytes_of(flat));
  std::vector<double> projective = scale_translate(1, 0, 0, 0);
  projective.insert(projective.end(), {0, 0, 1, 1});
  write_npy(dir_ / "projective.npy", "<f8", "(1, 4, 4)", bytes_of(projective));
  std::ofstream(dir_ / "text.npy") << "not an array";
  const std::string at = (dir_ / "scene.json").string() + ": /objects/1/instances";
  const auto with = [](const std::string& instances) {
    return R"({"shape": "ball", "instances": )" + instances + "}";
  };
  const auto file = [&](const std::string& name) {
    return error(with(R"({"file": ")" + name + R"("})"));
  };
  EXPECT_EQ(file("shape.npy"), at + "/file: shape.npy: holds an array of shape (3, 4); expected "
                                    "(N, 3) translations, (N, 3, 4) or (N, 4, 4) transforms");
  EXPECT_EQ(file("big.npy"), at + "/file: big.npy: holds '>f8' values; expected little-endian "
                                  "float64 ('<f8') or float32 ('<f4')");
  EXPECT_EQ(file("ints.npy"), at + "/file: ints.npy: holds '<i8' values; expected little-endian "
                                   "float64 ('<f8') or float32 ('<f4')");
  EXPECT_EQ(file("fortran.npy"),
            at + "/file: fortran.npy: is in Fortran order; save a C-ordered array");
  EXPECT_EQ(file("short.npy"),
            at + "/file: short.npy: has 96 bytes of data; an array of shape (2, 3, 4) needs 192");
  EXPECT_EQ(file("none.npy"), at + "/file: none.npy: holds no instances");
  EXPECT_EQ(file("huge.npy"), at + "/file: huge.npy: holds 100000000000 instances; an object "
                                   "may have at most 10000000");
  EXPECT_EQ(file("nan.npy"),
            at + "/file: nan.npy: instance 0: entry (0, 3) is nan; entries must be within ±1e+100");
  EXPECT_EQ(file("flat.npy"),
            at + "/file: flat.npy: instance 1: degenerate transform (determinant 0)");
  EXPECT_EQ(file("projective.npy"),
            at + "/file: projective.npy: instance 0: the last row is not 0 0 0 1 (only affine "
                 "transforms place a shape)");
  EXPECT_EQ(file("text.npy"), at + "/file: text.npy: not a .npy file (write it with numpy.save)");
  EXPECT_EQ(file("missing.npy"),
            at + "/file: missing.npy: cannot open file (No such file or directory)");
  EXPECT_EQ(file("."), at + "/file: .: cannot open file (is a directory)");
  EXPECT_EQ(file(""), at + "/file: must name a file");
  // Issue 44: the name was cut at the NUL, and shape.npy read.
  EXPECT_EQ(file(R"(shape.npy\u0000junk)"), at + "/file: a file name cannot hold a NUL byte");
  EXPECT_EQ(error(with("[]")), at + ": must hold at least one transform");
  EXPECT_EQ(error(with("3")), at + R"(: expected an array of transforms or {"file": "NAME.npy"})");
  EXPECT_EQ(error(with(R"({"file": "shape.npy", "fiel": 1})")),
            at + R"(/fiel: unknown key for instances from a file (did you mean "file"?))");
  EXPECT_EQ(error(with(R"([[], [{"scale": 0}]])")), at + "/1/0/scale: must be nonzero");
  // A placement whose coefficients overflow once composed with the shape's (a free form keeps
  // its quadrics' scale: only a surface's are normalised).
  const std::string thin = R"({"type": "freeform", "base": {"type": "quadric", "coefficients": )"
                           R"([-1e200, -1, -1, 0, 0, 0, 0, 0, 0, 1]}})";
  EXPECT_EQ(error(R"({"shape": )" + thin + R"(, "instances": [[{"translate": [1e100, 0, 0]}]]})"),
            (dir_ / "scene.json").string() +
                R"(: /objects/1/instances (instance 0): the transforms placing shape "inline" )"
                "compose beyond a double's range");
}

// The instances file is one of the files the render reads (its fingerprint, the outputs that
// must not overwrite it), and the memory estimate charges every copy.
TEST_F(Instances, TheFileIsAnInputAndCopiesAreCharged) {
  write_row(dir_ / "many.npy", 1000);
  const SceneDesc desc =
      load_scene_file(scene_file(R"({"shape": "rock", "instances": {"file": "many.npy"}})"));
  ASSERT_EQ(desc.inputs.size(), 1u);
  EXPECT_EQ(desc.inputs[0].pointer, "/objects/1/instances/file");
  EXPECT_EQ(desc.inputs[0].bytes, fs::file_size(dir_ / "many.npy"));
  std::vector<InputFile> read;
  const Scene scene = compile_scene(desc, {}, &read);
  EXPECT_EQ(scene.objects.size(), 1001u);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0].path, (dir_ / "many.npy").string());
  EXPECT_EQ(scene.objects.back().source, 1);

  // 1 000 free forms of five quadrics: a few MiB of objects, charged by the estimate.
  const double objects = object_memory(desc);
  EXPECT_GT(objects, 1000 * 1024.0);
  EXPECT_LT(objects, 8 * 1048576.0);
  EXPECT_NO_THROW(check_render_memory(desc, 1, uint64_t(objects) + (64 << 20)));
  try {
    check_render_memory(desc, 1, uint64_t(objects / 2));
    ADD_FAILURE() << "not refused";
  } catch (const JobError& e) {
    EXPECT_NE(std::string(e.what()).find(", objects "), std::string::npos) << e.what();
  }
}

// The objects' compile reports its progress, rising to 1.
TEST_F(Instances, TheObjectsCompileReportsItsProgress) {
  write_row(dir_ / "many.npy", 5000);
  const SceneDesc desc =
      load_scene_file(scene_file(R"({"shape": "ball", "instances": {"file": "many.npy"}})"));
  std::vector<double> seen;
  BuildMonitor monitor;
  monitor.objects = [&](double f) { seen.push_back(f); };
  compile_scene(desc, monitor);
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back(), 1.0);
  for (size_t i = 1; i < seen.size(); ++i) EXPECT_GT(seen[i], seen[i - 1]);
}

}  // namespace instances_test
}  // namespace nimbus
