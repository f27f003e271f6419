// Every scene shipped in scenes/ loads, compiles and renders a tiny image with finite values, so
// a change to the format or the loader cannot silently break them.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace nimbus {
namespace scenes_test {

std::vector<std::string> shipped_scenes() {
  std::vector<std::string> out;
  for (const char* dir : {"scenes", "scenes/bench"})
    for (const auto& e :
         std::filesystem::directory_iterator(std::string(NIMBUS_SOURCE_DIR) + "/" + dir))
      if (e.path().extension() == ".json") out.push_back(e.path().string());
  return out;
}

TEST(Scenes, EveryShippedSceneLoadsAndRenders) {
  const std::vector<std::string> scenes = shipped_scenes();
  ASSERT_GE(scenes.size(), 5u);
  for (const std::string& path : scenes) {
    SCOPED_TRACE(path);
    Scene scene;
    ASSERT_NO_THROW(scene = compile_scene(load_scene_file(
                        path, {"film.width=8", "film.height=6", "integrator.spp=1"})));
    const RenderResult r = render(scene);
    const MeanEstimate m = image_mean(r.film);
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(std::isfinite(m.mean[c]));
      EXPECT_GE(m.mean[c], 0);
    }
  }
}

}  // namespace scenes_test
}  // namespace nimbus
