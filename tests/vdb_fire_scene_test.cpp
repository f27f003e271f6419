// The shipped fire (scenes/vdb_fire.json, issue 14): its grids, "density" (soot) and
// "temperature" (kelvin) in scenes/vdb/vdb_fire.vdb, are made here and written with OpenVDB's
// API (support/vdb_grids.h) when NIMBUS_WRITE_SCENE_ASSETS=1. The test checks that the committed
// file holds what the generator makes, voxel for voxel, and that the scene loads and renders
// light from the fire.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "support/vdb_grids.h"

namespace nimbus {
namespace vdb_fire_scene_test {

const std::string kScenes = std::string(NIMBUS_SOURCE_DIR) + "/scenes/";

// Voxels of 0.04 over a flame 1.6 tall on a base of radius 0.35 standing on y = 0.
constexpr double kVoxel = 0.04, kHeight = 1.6, kBase = 0.35;

// The flame: a tapering column that sways with height; t in [0, 1] is how deep inside it a
// point is (0 at its edge), and the turbulence a sum of a few sines, fixed, so the file is
// reproducible everywhere.
struct FireSample {
  double density = 0, kelvin = 0;
};

FireSample fire_at(double x, double y, double z) {
  const double h = y / kHeight;
  if (h <= 0 || h >= 1) return {};
  const double sway = 0.12 * h * h * std::sin(5.0 * h + 0.6);
  const double radius = kBase * std::pow(1 - h, 0.6) * (1 + 0.25 * std::sin(9 * h));
  const double dx = x - sway, dz = z - 0.5 * sway;
  const double rho = std::sqrt(dx * dx + dz * dz);
  const double t = 1 - rho / radius;
  if (t <= 0) return {};
  const double turbulence = 0.75 + 0.25 * std::sin(17 * x + 11 * y) * std::cos(13 * z - 7 * y) +
                            0.1 * std::sin(31 * y + 23 * x - 19 * z);
  FireSample s;
  s.density = std::clamp(turbulence * (0.3 + 1.7 * h) * std::sqrt(t), 0.0, 2.0);
  // Hottest low in the core, cooling with height and towards the edge.
  s.kelvin = 800 + 1900 * std::pow(t, 0.7) * (1 - 0.55 * h) * std::clamp(turbulence, 0.6, 1.1);
  return s;
}

std::vector<test::FloatGrid> fire_grids() {
  test::FloatGrid density{
      .name = "density", .voxel = kVoxel, .grid_class = test::GridClass::kFogVolume};
  test::FloatGrid temperature{
      .name = "temperature", .voxel = kVoxel, .grid_class = test::GridClass::kFogVolume};
  const int r = int(std::ceil(0.6 / kVoxel)), top = int(std::ceil(kHeight / kVoxel));
  for (int i = -r; i <= r; ++i)
    for (int j = 0; j <= top; ++j)
      for (int l = -r; l <= r; ++l) {
        const FireSample s = fire_at(i * kVoxel, j * kVoxel, l * kVoxel);
        if (s.density <= 0) continue;
        density.voxels.push_back({{i, j, l}, float(s.density)});
        temperature.voxels.push_back({{i, j, l}, float(s.kelvin)});
      }
  return {density, temperature};
}

TEST(VdbFireScene, TheCommittedGridsAreTheGeneratorsAndTheSceneRendersFire) {
  const std::string file = kScenes + "vdb/vdb_fire.vdb";
  const std::vector<test::FloatGrid> made = fire_grids();
  if (std::getenv("NIMBUS_WRITE_SCENE_ASSETS")) test::write_vdb(file, made);
  ASSERT_TRUE(std::filesystem::exists(file)) << file << " (NIMBUS_WRITE_SCENE_ASSETS=1 writes it)";
  EXPECT_LT(std::filesystem::file_size(file), 400u << 10);
  for (const test::FloatGrid& want : made) {
    const std::optional<test::ReadFloatGrid> have = test::read_float_grid(file, want.name);
    ASSERT_TRUE(have) << want.name;
    // The made grid's voxels are distinct, each active: their number is its active voxel count.
    EXPECT_EQ(have->active_voxel_count, want.voxels.size()) << want.name;
    for (const auto& v : want.voxels)
      ASSERT_EQ(have->value(v.ijk), v.value) << want.name << " " << v.ijk;
  }

  SceneDesc desc = load_scene_file(kScenes + "vdb_fire.json");
  desc.settings.width = 24;
  desc.settings.height = 32;
  desc.settings.spp = 16;
  RenderOptions options;
  options.threads = 2;
  const RenderResult r = render(compile_scene(desc), options);
  EXPECT_EQ(r.counters.rejected_samples, 0u);
  // The fire is the brightest thing in view: its brightest pixel is orange, red over green over
  // blue, and bright (about 2 in red at 16 spp, against a sky of 0.004).
  Rgb brightest(0.0);
  for (int p = 0; p < r.film.pixels(); ++p) {
    const Rgb m = r.film.mean(p);
    for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(m[c])) << p;
    if (m.sum() > brightest.sum()) brightest = m;
  }
  EXPECT_GT(brightest[0], 1.0);
  EXPECT_GT(brightest[0], brightest[1]);
  EXPECT_GT(brightest[1], brightest[2]);
}

}  // namespace vdb_fire_scene_test
}  // namespace nimbus
