// `nimbus export-vdb` as a library call (io/vdb_export.h, issue 14), read back with OpenVDB: the
// file holds one fog volume "density" of voxel size H whose active voxels equal the medium's
// density at the voxel centres i H to float precision, sparse, with the medium's coefficients as
// metadata; the object is chosen as documented; a cancelled export writes nothing; and a
// field-density free form and its export render alike within the discretisation error.

#include "nimbus/io/vdb_export.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "nimbus/math/rng.h"
#include "nimbus/media/medium_field.h"
#include "nimbus/media/vdb_density.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "support/film_chi2.h"
#include "support/vdb_grids.h"

namespace nimbus {
namespace vdb_export_test {

using test::TempDir;

// A diffuse floor (no medium), then a cloud-density free form (a density that reads F) with a
// density scale of 3, HG phase and coloured coefficients.
const char* kCloudScene = R"({
  "camera": {"from": [0, 0.5, 5], "to": [0, 0, 0]},
  "shapes": {"blob": {"type": "freeform", "base": {"type": "ellipsoid", "radii": [1.2, 0.8, 0.9]},
                      "perturbations": [{"shape": {"type": "sphere", "center": [0.7, 0.4, 0],
                                                   "radius": 0.5}, "weight": 12}]}},
  "media": {"cloud": {"sigma_a": [0.1, 0.2, 0.3], "sigma_s": [4, 5, 6],
                      "phase": {"type": "hg", "g": 0.6},
                      "density": {"type": "cloud", "scale": 3, "frequency": 3, "seed": 2}}},
  "objects": [{"shape": {"type": "box", "min": [-3, -2, -3], "max": [3, -1.9, 3]}},
              {"shape": "blob", "medium": "cloud"}]
})";

// The file's grid "density", which must be its only grid and hold floats.
std::optional<test::ReadFloatGrid> read_density(const std::string& file) {
  EXPECT_EQ(test::vdb_grid_names(file).size(), 1u);
  std::optional<test::ReadFloatGrid> grid = test::read_float_grid(file, "density");
  EXPECT_TRUE(grid.has_value());
  return grid;
}

TEST(VdbExport, ActiveVoxelsHoldTheDensityAtVoxelCentres) {
  const TempDir dir("vdb_export");
  const SceneDesc desc = load_scene_json(nlohmann::json::parse(kCloudScene), "cloud.json");
  const int object = vdb_export_object(desc, -1);
  EXPECT_EQ(object, 1) << "the first object that holds a medium";
  const Scene scene = compile_scene(desc);
  const double h = 0.04;
  const VdbExportResult result = export_vdb(scene, object, h, dir.file("cloud.vdb"));
  EXPECT_FALSE(result.cancelled);

  const std::optional<test::ReadFloatGrid> grid = read_density(dir.file("cloud.vdb"));
  ASSERT_TRUE(grid.has_value());
  EXPECT_EQ(grid->grid_class, test::GridClass::kFogVolume);
  EXPECT_EQ(grid->background, 0.0f);
  EXPECT_TRUE(grid->linear);
  for (const test::Coord ijk : {test::Coord{0, 0, 0}, test::Coord{3, -7, 11}}) {
    const Vec3 w = grid->index_to_world(ijk);
    for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(w[k], ijk[k] * h);
  }
  EXPECT_EQ(grid->vec3s_metadata.at("sigma_a"), (std::array<float, 3>{0.1f, 0.2f, 0.3f}));
  EXPECT_EQ(grid->vec3s_metadata.at("sigma_s"), (std::array<float, 3>{4, 5, 6}));
  EXPECT_EQ(grid->float_metadata.at("phase_g"), 0.6f);
  EXPECT_EQ(test::vdb_file_metadata(dir.file("cloud.vdb"), "creator"), "nimbus " NIMBUS_VERSION);

  // Every voxel centre in the object's bounds, against the medium's density there.
  const SceneObject& obj = scene.objects[object];
  const Medium& medium = scene.media[obj.medium];
  const float threshold = float(kVdbExportThreshold * result.max_density);
  uint64_t centres = 0, active = 0;
  double largest = 0;
  const auto first = [&](int axis) { return int(std::ceil(obj.bounds.lo[axis] / h)); };
  const auto last = [&](int axis) { return int(std::floor(obj.bounds.hi[axis] / h)); };
  for (int i = first(0); i <= last(0); ++i)
    for (int j = first(1); j <= last(1); ++j)
      for (int k = first(2); k <= last(2); ++k) {
        ++centres;
        const Vec3 x{i * h, j * h, k * h};
        const double F = evaluate(obj.tape, x);
        const double expected = F > 0 ? medium_density(medium, x, F) : 0.0;
        largest = std::max(largest, expected);
        const test::Coord ijk{i, j, k};
        if (grid->is_on(ijk)) {
          ++active;
          ASSERT_EQ(grid->value(ijk), float(expected)) << i << " " << j << " " << k;
          EXPECT_GE(grid->value(ijk), threshold);
        } else {
          EXPECT_EQ(grid->value(ijk), 0.0f);
          EXPECT_LT(float(expected), threshold) << i << " " << j << " " << k;
        }
      }
  EXPECT_EQ(active, grid->active_voxel_count) << "no active voxel outside the bounds";
  EXPECT_EQ(active, result.active_voxels);
  EXPECT_EQ(result.max_density, double(float(largest)));
  EXPECT_GT(active, centres / 10);
  EXPECT_LT(active, centres / 2) << "the file is sparse";
  EXPECT_EQ(grid->active_tile_count, 0u);
}

TEST(VdbExport, TheObjectIsChosenAsDocumented) {
  const SceneDesc desc = load_scene_json(nlohmann::json::parse(kCloudScene), "cloud.json");
  EXPECT_EQ(vdb_export_object(desc, 1), 1);
  const auto message = [&](int requested) {
    try {
      vdb_export_object(desc, requested);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(message(0), "--object 0: cloud.json: /objects/0 holds no medium");
  EXPECT_EQ(message(2), "--object 2: cloud.json has 2 objects (0 to 1)");
  nlohmann::json no_media = nlohmann::json::parse(kCloudScene);
  no_media["objects"].erase(1);
  EXPECT_EQ(
      [&] {
        try {
          vdb_export_object(load_scene_json(no_media, "floor.json"), -1);
        } catch (const std::invalid_argument& e) {
          return std::string(e.what());
        }
        return std::string("(no error)");
      }(),
      "floor.json: no object holds a medium: there is nothing to export");
  // Voxel sizes that are not > 0, or far too small for the object, are refused before any work.
  const Scene scene = compile_scene(desc);
  EXPECT_THROW(export_vdb(scene, 1, 0, "unused.vdb"), std::invalid_argument);
  EXPECT_THROW(export_vdb(scene, 1, -0.1, "unused.vdb"), std::invalid_argument);
  EXPECT_THROW(export_vdb(scene, 1, 1e-4, "unused.vdb"), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists("unused.vdb"));
}

TEST(VdbExport, ACancelledExportWritesNothing) {
  const TempDir dir("vdb_export_cancel");
  const Scene scene =
      compile_scene(load_scene_json(nlohmann::json::parse(kCloudScene), "cloud.json"));
  BuildMonitor monitor;
  std::atomic<double> last{0};
  monitor.progress = [&](double f) {
    EXPECT_GE(f, last.load());
    last = f;
  };
  monitor.cancel = [&] { return last.load() > 0.3; };
  EXPECT_TRUE(export_vdb(scene, 1, 0.02, dir.file("cut.vdb"), monitor).cancelled);
  EXPECT_LT(last.load(), 1.0);
  EXPECT_FALSE(std::filesystem::exists(dir.file("cut.vdb")));
  EXPECT_TRUE(std::filesystem::is_empty(dir.path())) << "no temporary file is left";
}

// A free form filled with the field density (max(F, 0), scale 2), and the same medium from the
// free form's export held by a box around it. Independent samples: the comparison's tolerance
// comes from the images' sample variances.
const char* kFieldScene = R"({
  "film": {"width": 16, "height": 12},
  "camera": {"from": [0, 0.6, 4.5], "to": [0, 0, 0], "fov": 40},
  "integrator": {"spp": 1024, "seed": 1, "sampler": "independent"},
  "lights": [{"type": "environment", "radiance": [0.6, 0.7, 0.9]}],
  "shapes": {"blob": {"type": "freeform", "base": {"type": "sphere", "radius": 1},
                      "perturbations": [{"shape": {"type": "sphere", "center": [0.8, 0.3, 0],
                                                   "radius": 0.5}, "weight": 20}]}},
  "media": {"haze": {"sigma_a": 1, "sigma_s": [0.3, 0.5, 0.7], "phase": {"type": "hg", "g": 0.3},
                     "density": {"type": "field", "scale": 2}}},
  "objects": [{"shape": "blob", "medium": "haze"}]
})";

nlohmann::json vdb_version(const std::string& file, double scale = 1) {
  nlohmann::json j = nlohmann::json::parse(kFieldScene);
  j["media"]["haze"]["density"] = {{"type", "vdb"}, {"file", file}, {"scale", scale}};
  j["objects"][0]["shape"] = {
      {"type", "box"}, {"min", {-1.3, -1.3, -1.3}}, {"max", {1.5, 1.3, 1.3}}};
  return j;
}

// The largest difference in optical depth (density integrated along the ray) between the field
// and a grid, over rays through the free form; midpoint rule with steps far below the voxel.
double largest_depth_error(const Scene& field, const Density& grid, double h) {
  const SceneObject& obj = field.objects[0];
  const Medium& medium = field.media[obj.medium];
  Rng rng(8);
  double worst = 0;
  for (int r = 0; r < 150; ++r) {
    const Vec3 o{-2.0, -0.9 + 1.8 * rng.uniform(), -0.9 + 1.8 * rng.uniform()};
    const Vec3 d = normalize(Vec3{1, 0.3 * (rng.uniform() - 0.5), 0.3 * (rng.uniform() - 0.5)});
    const double step = h / 16;
    double tau_field = 0, tau_grid = 0;
    for (double t = 0.5 * step; t < 4.5; t += step) {
      const Vec3 x = o + d * t;
      const double F = evaluate(obj.tape, x);
      if (F > 0) tau_field += medium_density(medium, x, F) * step;
      tau_grid += grid.value(x, 1) * step;
    }
    worst = std::max(worst, std::abs(tau_grid - tau_field));
  }
  return worst;
}

// The discretisation error of trilinear interpolation is second order in the voxel size, also
// across the field's kink at the surface (there the error is O(H) over a band O(H) wide): the
// largest optical depth error Δτ over rays through the free form at H = 1/40 must be at most a
// third of that at H = 1/20 (a quarter expected), and below 0.01 (the optical depths reach about
// 5). The bound the renders are held to follows from it: where the media differ by at most Δτ
// along any ray, a pixel's attenuated radiance differs by a factor within e^±Δτ, so the image
// means may differ by L̄ Δτ plus 4 standard errors of the difference. The same grid 20 % denser
// must break that bound: the test can see an error of that size.
TEST(VdbExport, AFieldFreeFormAndItsExportRenderAlike) {
  const TempDir dir("vdb_round_trip");
  const Scene field = compile_scene(load_scene_json(nlohmann::json::parse(kFieldScene), "f.json"));
  double error[2];
  const double sizes[2] = {1.0 / 20, 1.0 / 40};
  for (int n = 0; n < 2; ++n) {
    const std::string file = dir.file("field" + std::to_string(n) + ".vdb");
    export_vdb(field, 0, sizes[n], file);
    VdbParams p;
    p.file = file;
    error[n] = largest_depth_error(field, *make_vdb_density(p), sizes[n]);
  }
  EXPECT_GT(error[1], 0);
  EXPECT_LT(error[1], error[0] / 3) << error[0] << " at H = 1/20, " << error[1] << " at 1/40";
  EXPECT_LT(error[1], 0.01);

  const auto render_scene = [&](const nlohmann::json& j, uint64_t seed) {
    nlohmann::json s = j;
    s["integrator"]["seed"] = seed;
    RenderOptions options;
    options.threads = 2;
    return render(compile_scene(load_scene_json(s, "s.json")), options).film;
  };
  const Film a = render_scene(nlohmann::json::parse(kFieldScene), 1);
  const Film b = render_scene(vdb_version(dir.file("field1.vdb")), 2);
  const Film denser = render_scene(vdb_version(dir.file("field1.vdb"), 1.2), 2);
  const MeanEstimate ma = image_mean(a), mb = image_mean(b), md = image_mean(denser);
  for (int ch = 0; ch < 3; ++ch) {
    const auto bound = [&](const MeanEstimate& m) {
      return ma.mean[ch] * error[1] + 4 * std::hypot(ma.standard_error[ch], m.standard_error[ch]);
    };
    EXPECT_LT(std::abs(mb.mean[ch] - ma.mean[ch]), bound(mb)) << "channel " << ch;
    EXPECT_GT(std::abs(md.mean[ch] - ma.mean[ch]), bound(md)) << "channel " << ch;
  }
}

// scenes/vdb_cloud.json renders the grid scenes/vdb/vdb_cloud.vdb, the cloud of
// scenes/cloud_sunlit.json as export-vdb writes it (the command is in the scene's comment): the
// shipped file must be what the exporter makes today, and the scene must load and render.
TEST(VdbExport, TheShippedExampleIsTheExportOfItsSourceScene) {
  const TempDir dir("vdb_example");
  const std::string scenes = std::string(NIMBUS_SOURCE_DIR) + "/scenes/";
  const Scene source = compile_scene(load_scene_file(scenes + "cloud_sunlit.json"));
  export_vdb(source, 0, 0.03, dir.file("fresh.vdb"));
  const auto shipped = read_density(scenes + "vdb/vdb_cloud.vdb");
  const auto fresh = read_density(dir.file("fresh.vdb"));
  ASSERT_TRUE(shipped && fresh);
  EXPECT_EQ(shipped->active_voxel_count, fresh->active_voxel_count);
  EXPECT_EQ(shipped->voxel_size, fresh->voxel_size);
  uint64_t differ = 0;
  for (const auto& v : shipped->active)
    differ += !fresh->is_on(v.ijk) || fresh->value(v.ijk) != v.value;
  EXPECT_EQ(differ, 0u) << "regenerate it with the command in scenes/vdb_cloud.json";

  Scene scene;
  ASSERT_NO_THROW(
      scene = compile_scene(load_scene_file(
          scenes + "vdb_cloud.json", {"film.width=8", "film.height=6", "integrator.spp=1"})));
  const MeanEstimate m = image_mean(render(scene).film);
  for (int c = 0; c < 3; ++c) EXPECT_TRUE(std::isfinite(m.mean[c]) && m.mean[c] > 0);
}

}  // namespace vdb_export_test
}  // namespace nimbus
