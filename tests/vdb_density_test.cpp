// The "vdb" density (media/vdb_density.h, issue 14) against grids written in the test with
// OpenVDB's own API: trilinear interpolation reproduces a linear density exactly, with a non-unit
// voxel size, an offset and a further transform; a slab of it clipped by a box renders exp(−τ)
// pixel by pixel (placement and orientation on the image); range() from the tree holds every
// value and lies within the extremes of the voxels it must cover; a sparse grid's empty tiles
// bound to 0 and cost no lookup; .nvdb files read as their .vdb; every kind of bad input is one
// SceneError line naming the JSON path and the file.

#include "nimbus/media/vdb_density.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>

#include "nimbus/math/rng.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "support/film_chi2.h"
#include "support/vdb_grids.h"

namespace nimbus {
namespace vdb_density_test {

using test::ball_value;
using test::linear_value;
using test::TempDir;

Vec3 random_in(Rng& rng, const Vec3& lo, const Vec3& hi) {
  return {lo.x + rng.uniform() * (hi.x - lo.x), lo.y + rng.uniform() * (hi.y - lo.y),
          lo.z + rng.uniform() * (hi.z - lo.z)};
}

DensityPtr vdb(const std::string& file, const Mat4& transform = Mat4::identity()) {
  VdbParams p;
  p.file = file;
  p.transform = transform;
  return make_vdb_density(p);
}

// Voxel size 0.1, index (0, 0, 0) at (1, -2, 0.5): voxels -4..20 active on every axis.
constexpr double kVoxel = 0.1;
const Vec3 kOffset{1, -2, 0.5};

Vec3 world_of(const Vec3& index) {
  return kOffset + kVoxel * index;
}

TEST(VdbDensity, TrilinearInterpolationReproducesALinearDensity) {
  const TempDir dir("vdb_linear");
  test::write_linear_vdb(dir.file("linear.vdb"), -4, 20, kVoxel, kOffset);
  const DensityPtr d = vdb(dir.file("linear.vdb"));
  EXPECT_FALSE(d->uses_F());
  // At voxel centres the voxel's value, between them the linear function: every point whose 8
  // blended voxels are active.
  for (int i = -4; i <= 20; i += 3)
    for (int j = -4; j <= 20; j += 4)
      for (int k = -4; k <= 20; k += 5)
        EXPECT_NEAR(d->value(world_of({double(i), double(j), double(k)}), 1), linear_value(i, j, k),
                    1e-12)
            << i << " " << j << " " << k;
  Rng rng(1);
  for (int n = 0; n < 5000; ++n) {
    const Vec3 u = random_in(rng, {-4, -4, -4}, {20, 20, 20});
    EXPECT_NEAR(d->value(world_of(u), 1), linear_value(u.x, u.y, u.z), 1e-12) << u.x;
  }
  // Inactive voxels are 0: half a voxel beyond the active ones the value is half the edge's, and
  // more than a voxel beyond it is 0.
  EXPECT_NEAR(d->value(world_of({-4.5, 5, 7}), 1), 0.5 * linear_value(-4, 5, 7), 1e-12);
  EXPECT_NEAR(d->value(world_of({3, 20.25, 7}), 1), 0.75 * linear_value(3, 20, 7), 1e-12);
  EXPECT_EQ(d->value(world_of({-5.01, 5, 7}), 1), 0.0);
  EXPECT_EQ(d->value(world_of({3, 5, 21.2}), 1), 0.0);
  EXPECT_EQ(d->value({1e9, 0, 0}, 1), 0.0);
}

TEST(VdbDensity, TheDensityTransformMovesTheGridFurther) {
  const TempDir dir("vdb_transform");
  test::write_linear_vdb(dir.file("linear.vdb"), -4, 20, kVoxel, kOffset);
  const Mat4 m = Mat4::translate({3, -1, 2}) * Mat4::rotate({0, 0, 1}, 90) * Mat4::scale({2, 2, 2});
  const DensityPtr moved = vdb(dir.file("linear.vdb"), m);
  Rng rng(2);
  for (int n = 0; n < 1000; ++n) {
    const Vec3 u = random_in(rng, {-4, -4, -4}, {20, 20, 20});
    // The grid's world point x goes to m x.
    EXPECT_NEAR(moved->value(transform_point(m, world_of(u)), 1), linear_value(u.x, u.y, u.z),
                1e-11);
  }
  // Rotated by 90° about z: the grid's +x axis now points along +y.
  const Vec3 p = transform_point(m, world_of({8, 8, 8}));
  EXPECT_NEAR(moved->value(p + Vec3{0, 2 * kVoxel, 0}, 1), linear_value(9, 8, 8), 1e-11);
  EXPECT_NEAR(moved->value(p - Vec3{2 * kVoxel, 0, 0}, 1), linear_value(8, 9, 8), 1e-11);
}

// An absorbing slab of the linear density, clipped by a box and seen along −z by an orthographic
// camera against a white sky: each pixel is the mean of exp(−τ(x, y)) over its footprint, with
// τ = σ_a ∫ d dz = σ_a Δz d(x, y, z_mid) because d is linear. Pixel by pixel the render must
// agree with that (chi-square), and must not with the image mirrored in x: a grid placed or
// oriented wrongly fails. The scene names the grid relative to its own folder.
TEST(VdbDensity, SlabTransmittanceIsExpMinusTauOnTheImage) {
  const TempDir dir("vdb_slab");
  test::write_linear_vdb(dir.file("linear.vdb"), -4, 20, kVoxel, {0, 0, 0});
  const double sigma_a = 0.15, z0 = 0.4, z1 = 1.0;
  const int size = 8;
  const Vec3 view_lo{0.3, 0.4, 0}, view_hi{1.3, 1.4, 0};
  std::ofstream(dir.file("slab.json")) << R"({
    "film": {"width": 8, "height": 8},
    "camera": {"type": "orthographic", "from": [0.8, 0.9, 3], "to": [0.8, 0.9, 0], "width": 1.0},
    "integrator": {"spp": 2048, "seed": 5, "sampler": "independent"},
    "lights": [{"type": "environment", "radiance": 1}],
    "media": {"slab": {"sigma_a": 0.15, "density": {"type": "vdb", "file": "linear.vdb"}}},
    "objects": [{"shape": {"type": "box", "min": [0.2, 0.3, 0.4], "max": [1.4, 1.5, 1.0]},
                 "medium": "slab"}]
  })";
  const Scene scene = compile_scene(load_scene_file(dir.file("slab.json")));
  RenderOptions options;
  options.threads = 2;
  const RenderResult result = render(scene, options);
  // d = linear_value(x / h, y / h, z / h) = 4 + 5x + 2.5y + 1.25z.
  const auto tau = [&](double x, double y) {
    return sigma_a * (z1 - z0) * linear_value(x / kVoxel, y / kVoxel, 0.5 * (z0 + z1) / kVoxel);
  };
  // The mean of exp(−τ) over [x0, x0 + w] × [y0, y0 + w], τ linear in x and y.
  const auto mean_transmittance = [&](double x0, double y0, double w) {
    const auto f = [](double u) { return (1 - std::exp(-u)) / u; };
    const double bx = tau(x0 + w, y0) - tau(x0, y0), by = tau(x0, y0 + w) - tau(x0, y0);
    return std::exp(-tau(x0, y0)) * f(bx) * f(by);
  };
  const double w = (view_hi.x - view_lo.x) / size;
  // Per pixel, the z-score of the render against the reference (its sample variance is that of
  // independent samples: the scene asks for them), and against the reference
  // mirrored in x (a grid placed the wrong way round), one channel (they are equal).
  test::Chi2 right, mirrored;
  for (int py = 0; py < size; ++py)
    for (int px = 0; px < size; ++px) {
      // Row 0 is the top of the image: the largest y.
      const double x0 = view_lo.x + px * w, y0 = view_hi.y - (py + 1) * w;
      const int pixel = py * size + px;
      const double mean = result.film.mean(pixel)[0], var = result.film.variance_of_mean(pixel)[0];
      EXPECT_LT(std::sqrt(var), 0.012) << "pixel " << px << ", " << py;
      test::add_z(right, mean - mean_transmittance(x0, y0, w), var);
      test::add_z(mirrored, mean - mean_transmittance(view_hi.x - (px + 1) * w, y0, w), var);
    }
  EXPECT_TRUE(right.passes()) << right.value << " for " << right.dof;
  EXPECT_FALSE(mirrored.passes()) << mirrored.value << " for " << mirrored.dof;
}

// The voxels that interpolation may blend anywhere in a box lie in [floor(lo), floor(hi) + 1] of
// its index-space hull; a bound over a few more on each side must still enclose range().
struct VoxelExtremes {
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
};

VoxelExtremes ball_extremes(const Vec3& index_lo, const Vec3& index_hi, int radius) {
  VoxelExtremes e;
  for (int i = int(std::floor(index_lo.x)) - 1; i <= int(std::floor(index_hi.x)) + 2; ++i)
    for (int j = int(std::floor(index_lo.y)) - 1; j <= int(std::floor(index_hi.y)) + 2; ++j)
      for (int k = int(std::floor(index_lo.z)) - 1; k <= int(std::floor(index_hi.z)) + 2; ++k) {
        const double v = ball_value(i, j, k, radius);
        e.lo = std::min(e.lo, v);
        e.hi = std::max(e.hi, v);
      }
  return e;
}

TEST(VdbDensity, RangeFromTheTreeHoldsEveryValueAndIsTight) {
  const TempDir dir("vdb_range");
  const int radius = 20;
  const double h = 0.05;
  const Vec3 center{0.1, -0.2, 0.3};
  test::write_ball_vdb(dir.file("ball.vdb"), radius, h, center);
  const DensityPtr d = vdb(dir.file("ball.vdb"));
  Rng rng(4);
  int positive_lo = 0, leaf_border = 0;
  for (int b = 0; b < 600; ++b) {
    // Boxes from a fraction of a voxel to half the ball, many across leaf borders (every 8
    // voxels), some inside the ball, some reaching out of it.
    const double size = h * std::pow(2.0, -2 + 7 * rng.uniform());
    const Vec3 lo = random_in(rng, center - Vec3{1.1, 1.1, 1.1}, center + Vec3{0.9, 0.9, 0.9});
    const Box box{lo, lo + Vec3{size, size * (0.5 + rng.uniform()), size}};
    const Interval r = d->range(box, {1, 1});
    const Vec3 ilo = (box.lo - center) * (1 / h), ihi = (box.hi - center) * (1 / h);
    const VoxelExtremes near = ball_extremes(ilo, ihi, radius);
    ASSERT_LE(0, r.lo);
    ASSERT_LE(r.lo, r.hi);
    EXPECT_LE(near.lo * (1 - 1e-13), r.lo) << "box " << b;
    EXPECT_LE(r.hi, near.hi * (1 + 1e-13)) << "box " << b;
    positive_lo += r.lo > 0;
    leaf_border += std::floor(ilo.x / 8) != std::floor((ihi.x + 1) / 8);
    for (int n = 0; n < 60; ++n) {
      const double v = d->value(random_in(rng, box.lo, box.hi), 1);
      EXPECT_LE(r.lo, v) << "box " << b;
      EXPECT_GE(r.hi, v) << "box " << b;
    }
  }
  EXPECT_GT(positive_lo, 20) << "boxes inside the ball should have a positive lower bound";
  EXPECT_GT(leaf_border, 100);

  // A box inside one leaf's last voxels still reaches into the next leaf: the value at x = 7.5
  // blends voxels 7 and 8, and voxel 8 lies in the next leaf.
  test::FloatGrid g{.name = "density"};
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) g.voxels.push_back({{i, j, k}, i == 8 ? 9.0f : 1.0f});
  test::write_vdb(dir.file("step.vdb"), {g});
  const DensityPtr step = vdb(dir.file("step.vdb"));
  const Interval r = step->range({{7.2, 1.2, 1.2}, {7.8, 1.8, 1.8}}, {1, 1});
  EXPECT_NEAR(step->value({7.5, 1.5, 1.5}, 1), 5.0, 1e-12);
  EXPECT_NEAR(r.hi, 9.0, 1e-9);
  EXPECT_NEAR(r.lo, 1.0, 1e-9);
  // Within voxel 2's cell only voxels 2 and 3 (both 1) blend: the bound is exact.
  const Interval flat = step->range({{2.2, 1.2, 1.2}, {2.8, 1.8, 1.8}}, {1, 1});
  EXPECT_NEAR(flat.lo, 1.0, 1e-9);
  EXPECT_NEAR(flat.hi, 1.0, 1e-9);
}

// Two small blobs 4000 voxels apart and an active tile of 128³ voxels (a lower internal node)
// between them; everything else empty.
TEST(VdbDensity, ASparseGridsEmptyTilesBoundToZeroAndCostNoLookup) {
  const TempDir dir("vdb_sparse");
  test::FloatGrid g{.name = "density", .voxel = 1.0};
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 6; ++k) {
        g.voxels.push_back({{i, j, k}, 0.5f + 0.1f * float(i)});
        g.voxels.push_back({{4000 + i, j, k}, 2.0f});
      }
  // An active tile in an upper internal node (level 2): 128³ voxels of 0.25, no leaf.
  g.tiles.push_back({2, {1024, 0, 0}, 0.25f});
  test::write_vdb(dir.file("sparse.vdb"), {g});
  const DensityPtr d = vdb(dir.file("sparse.vdb"));

  EXPECT_NEAR(d->value({2, 2, 2}, 1), 0.7, 1e-6);
  EXPECT_NEAR(d->value({1100.3, 60.7, 3.2}, 1), 0.25, 1e-7);
  EXPECT_EQ(d->value({500, 2, 2}, 1), 0.0);
  // Empty space between the blobs: no medium at all.
  const Interval empty = d->range({{100, -50, -50}, {900, 50, 50}}, {1, 1});
  EXPECT_EQ(empty.lo, 0.0);
  EXPECT_EQ(empty.hi, 0.0);
  // Inside the tile (more than a voxel from its edges) the tile's value bounds both ways.
  const Interval tile = d->range({{1030, 10, 10}, {1140, 100, 100}}, {1, 1});
  EXPECT_NEAR(tile.lo, 0.25, 1e-12);
  EXPECT_NEAR(tile.hi, 0.25, 1e-12);
  // Across the tile's edge into empty space: 0 below, the tile above.
  const Interval edge = d->range({{1140, 10, 10}, {1160, 20, 20}}, {1, 1});
  EXPECT_EQ(edge.lo, 0.0);
  EXPECT_NEAR(edge.hi, 0.25, 1e-12);
  // The first blob: its largest voxel (1.0 at i = 5) and 0 around it.
  const Interval blob = d->range({{-3, -3, -3}, {10, 10, 10}}, {1, 1});
  EXPECT_EQ(blob.lo, 0.0);
  EXPECT_NEAR(blob.hi, 1.0, 1e-6);
  // The whole grid.
  const Interval all = d->range({{-10, -10, -10}, {4100, 200, 200}}, {1, 1});
  EXPECT_NEAR(all.hi, 2.0, 1e-12);

  // Rendered: rays through the empty tiles between the blobs look up no density (the octree
  // marks their nodes empty); rays through the tile do, which shows the count can rise. (In a
  // medium thin enough the octree may rightly keep a few nulls rather than split: its cost model,
  // media/octree.h.)
  const auto lookups = [&](double x) {
    std::ofstream(dir.file("sparse.json"))
        << R"({
      "film": {"width": 4, "height": 4},
      "camera": {"type": "orthographic", "from": [)"
        << x << R"(, 60, 300], "to": [)" << x << R"(, 60, 0], "width": 20},
      "integrator": {"spp": 4, "octree": {"depth": 8}},
      "lights": [{"type": "environment", "radiance": 1}],
      "media": {"m": {"sigma_s": 1, "density": {"type": "vdb", "file": "sparse.vdb"}}},
      "objects": [{"shape": {"type": "box", "min": [-8, -8, -8], "max": [4100, 136, 136]},
                   "medium": "m"}]
    })";
    const Scene scene = compile_scene(load_scene_file(dir.file("sparse.json")));
    RenderOptions options;
    options.threads = 1;
    return render(scene, options).counters.tracking.lookups;
  };
  EXPECT_EQ(lookups(500), 0u);
  EXPECT_GT(lookups(1100), 0u);
}

TEST(VdbDensity, NanoVdbFilesReadAsTheirOpenVdbFiles) {
  const TempDir dir("vdb_nano");
  test::write_ball_vdb(dir.file("ball.vdb"), 16, 0.05, {0.3, 0.1, -0.2});
  test::write_nvdb(dir.file("ball.vdb"), dir.file("ball.nvdb"));
  const DensityPtr a = vdb(dir.file("ball.vdb")), b = vdb(dir.file("ball.nvdb"));
  Rng rng(6);
  for (int n = 0; n < 2000; ++n) {
    const Vec3 x = random_in(rng, {-0.6, -0.8, -1.1}, {1.2, 1.0, 0.7});
    EXPECT_EQ(a->value(x, 1), b->value(x, 1));
    const Box box{x, x + Vec3{0.1, 0.2, 0.05} * rng.uniform()};
    EXPECT_EQ(a->range(box, {1, 1}).hi, b->range(box, {1, 1}).hi);
    EXPECT_EQ(a->range(box, {1, 1}).lo, b->range(box, {1, 1}).lo);
  }
}

TEST(VdbDensity, DoubleGridsInactiveAndNegativeValues) {
  const TempDir dir("vdb_double");
  test::DoubleGrid g{.name = "density", .background = 3.0};  // a background that is not 0
  g.active.push_back({{0, 0, 0}, 2.0});
  g.active.push_back({{1, 0, 0}, -1.0});   // negative: read as 0
  g.inactive.push_back({{0, 1, 0}, 5.0});  // inactive: read as 0
  test::write_double_vdb(dir.file("double.vdb"), g);
  const DensityPtr d = vdb(dir.file("double.vdb"));
  EXPECT_EQ(d->value({0, 0, 0}, 1), 2.0);
  EXPECT_EQ(d->value({1, 0, 0}, 1), 0.0);
  EXPECT_EQ(d->value({0, 1, 0}, 1), 0.0);
  EXPECT_EQ(d->value({0, 0, 1}, 1), 0.0);
  EXPECT_EQ(d->value({50, 50, 50}, 1), 0.0);
  EXPECT_NEAR(d->value({0.5, 0, 0}, 1), 1.0, 1e-12);
  const Interval r = d->range({{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}}, {1, 1});
  EXPECT_EQ(r.lo, 0.0);
  EXPECT_NEAR(r.hi, 2.0, 1e-12);
}

// The error of a scene in `dir` whose medium has the given density.
std::string load_error(const TempDir& dir, const std::string& density) {
  std::ofstream(dir.file("scene.json"))
      << R"({"camera": {"from": [0, 0, 5], "to": [0, 0, 0]}, "media": {"m": {"density": )"
      << density << "}}}";
  try {
    compile_scene(load_scene_file(dir.file("scene.json")));  // the grid is read by compiling
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(VdbDensity, BadInputIsOneLineNamingTheJsonPathAndTheFile) {
  const TempDir dir("vdb_errors");
  const std::string scene = dir.file("scene.json") + ": /media/m/density";
  const auto in_dir = [&](const std::string& name) { return dir.file(name); };
  // A grid named `name` whose one voxel (0, 0, 0) holds 1.
  const auto one_voxel = [](const std::string& name) {
    return test::FloatGrid{.name = name, .voxels = {{{0, 0, 0}, 1.0f}}};
  };

  // Two grids, neither named "density".
  test::write_vdb(in_dir("two.vdb"), {one_voxel("smoke"), one_voxel("temperature")});
  // A grid of vectors.
  test::write_vec3s_vdb(in_dir("vectors.vdb"), "density", {0, 0, 0}, {1, 0, 0});
  // A level set.
  test::write_level_set_sphere_vdb(in_dir("levelset.vdb"), "density", 1.0, 0.1);
  // A frustum transform.
  test::write_frustum_vdb(in_dir("frustum.vdb"), one_voxel("density"), {0, 0, 0}, {10, 10, 10}, 0.5,
                          2.0);
  // A value that is not finite.
  test::FloatGrid nan = one_voxel("density");
  nan.voxels.push_back({{1, 2, 3}, std::numeric_limits<float>::quiet_NaN()});
  test::write_vdb(in_dir("nan.vdb"), {nan});
  // Not VDB, and VDB cut short.
  std::ofstream(in_dir("text.vdb")) << "a cloud, honestly\n";
  test::write_ball_vdb(in_dir("ball.vdb"), 16, 0.1, {0, 0, 0});
  const auto bytes = std::filesystem::file_size(in_dir("ball.vdb"));
  std::filesystem::copy_file(in_dir("ball.vdb"), in_dir("cut.vdb"));
  std::filesystem::resize_file(in_dir("cut.vdb"), bytes * 2 / 3);
  // NanoVDB cut short, and NanoVDB with a wild child offset.
  test::write_nvdb(in_dir("ball.vdb"), in_dir("ball.nvdb"));
  test::write_nvdb_with_wild_children(in_dir("ball.vdb"), in_dir("wild.nvdb"));
  std::filesystem::copy_file(in_dir("ball.nvdb"), in_dir("cut.nvdb"));
  std::filesystem::resize_file(in_dir("cut.nvdb"),
                               std::filesystem::file_size(in_dir("ball.nvdb")) / 2);

  struct Case {
    std::string density, expected;
  };
  const Case cases[] = {
      {R"({"type": "vdb", "file": "nowhere.vdb"})",
       scene + "/file: " + in_dir("nowhere.vdb") +
           ": cannot open file (No such file or directory)"},
      {R"({"type": "vdb", "file": "."})",
       scene + "/file: " + in_dir(".") + ": cannot open file (is a directory)"},
      {R"({"type": "vdb", "file": "text.vdb"})",
       scene + "/file: " + in_dir("text.vdb") +
           ": not a VDB file (it starts with neither OpenVDB's nor NanoVDB's magic number)"},
      {R"({"type": "vdb", "file": "two.vdb"})",
       scene + ": " + in_dir("two.vdb") +
           R"(: grid "density" is not in the file (the file holds grids "smoke", "temperature"))"},
      {R"({"type": "vdb", "file": "two.vdb", "grid": "fire"})",
       scene + "/grid: " + in_dir("two.vdb") +
           R"(: grid "fire" is not in the file (the file holds grids "smoke", "temperature"))"},
      {R"({"type": "vdb", "file": "vectors.vdb"})",
       scene + ": " + in_dir("vectors.vdb") +
           R"(: grid "density" holds vec3s values; a density grid holds float or double values)"},
      {R"({"type": "vdb", "file": "levelset.vdb"})",
       scene + ": " + in_dir("levelset.vdb") +
           R"(: grid "density" is a level set (signed distances), not a density; convert it to a fog volume first (OpenVDB's tools::sdfToFogVolume))"},
      {R"({"type": "vdb", "file": "frustum.vdb"})",
       scene + ": " + in_dir("frustum.vdb") +
           R"(: grid "density" has a non-linear transform (NonlinearFrustumMap); only linear (affine) grid transforms are supported)"},
      {R"({"type": "vdb", "file": "nan.vdb"})",
       scene + ": " + in_dir("nan.vdb") +
           R"(: grid "density" holds the value nan at voxel (1, 2, 3); a density must be finite)"},
      {R"({"type": "vdb", "file": "cut.vdb"})", scene + "/file: " + in_dir("cut.vdb") + ": "},
      {R"({"type": "vdb", "file": "cut.nvdb"})", scene + "/file: " + in_dir("cut.nvdb") + ": "},
      {R"({"type": "vdb", "file": "wild.nvdb"})",
       scene + "/file: " + in_dir("wild.nvdb") +
           ": corrupted NanoVDB file (a node lies outside its grid)"},
      {R"({"type": "vdb", "file": ""})", scene + "/file: must name a file"},
      {R"({"type": "vdb", "file": "nan.vdb\u0000junk"})",
       scene + "/file: a file name cannot hold a NUL byte"},
      {R"({"type": "voxels"})",
       scene +
           R"(/type: unknown density type "voxels" (expected one of: constant, field, cloud, vdb, noise, turbulence, veins))"},
      {R"({"type": "vdb"})", scene + "/file: required key is missing"},
      // A misspelt key is reported before the file is read with the default grid.
      {R"({"type": "vdb", "file": "nowhere.vdb", "gird": "x"})",
       scene + R"(/gird: unknown key for density type "vdb" (did you mean "grid"?))"},
      {R"({"type": "vdb", "file": "ball.vdb", "transform": [{"scale": 0}]})",
       scene + "/transform/0/scale: must be nonzero"},
  };
  for (const Case& c : cases) {
    const std::string e = load_error(dir, c.density);
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    if (c.expected.back() == ' ')
      EXPECT_EQ(e.rfind(c.expected, 0), 0u) << e;  // the library's words follow
    else
      EXPECT_EQ(e, c.expected);
  }
  // The good files load, through the same path.
  EXPECT_EQ(load_error(dir, R"({"type": "vdb", "file": "ball.vdb"})"), "(no error)");
  EXPECT_EQ(load_error(dir, R"({"type": "vdb", "file": "ball.nvdb"})"), "(no error)");
  EXPECT_EQ(load_error(dir, R"({"type": "vdb", "file": "two.vdb", "grid": "smoke"})"),
            "(no error)");
}

}  // namespace vdb_density_test
}  // namespace nimbus
