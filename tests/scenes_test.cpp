// Every scene shipped in scenes/ loads, compiles and renders a tiny image with finite values, so
// a change to the format or the loader cannot silently break them.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

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

// compile_scene compiles the objects' tapes in parallel: on one thread and on all, the same
// objects in the same order, to the bit (the scene at scale: 1 224 objects, 24 free forms).
TEST(Scenes, ObjectsCompileTheSameOnOneThreadAsOnMany) {
  const SceneDesc desc =
      load_scene_file(std::string(NIMBUS_SOURCE_DIR) + "/scenes/lanterns.json", {});
  Scene one;
  {
    const tbb::global_control serial(tbb::global_control::max_allowed_parallelism, 1);
    one = compile_scene(desc);
  }
  const Scene many = compile_scene(desc);
  ASSERT_EQ(one.objects.size(), desc.objects.size());
  ASSERT_EQ(many.objects.size(), one.objects.size());
  for (size_t i = 0; i < one.objects.size(); ++i) {
    const SceneObject &a = one.objects[i], &b = many.objects[i];
    ASSERT_EQ(a.bounds.lo, b.bounds.lo) << i;
    ASSERT_EQ(a.bounds.hi, b.bounds.hi) << i;
    ASSERT_EQ(a.tape.code.size(), b.tape.code.size()) << i;
    ASSERT_EQ(a.tape.quadrics.size(), b.tape.quadrics.size()) << i;
    for (size_t q = 0; q < a.tape.quadrics.size(); ++q)
      ASSERT_EQ(a.tape.quadrics[q].a, b.tape.quadrics[q].a) << i;
  }
}

// A cancel (Ctrl-C in the command line) stops the objects' compile, not only the octrees'
// build that follows it: cancelled from the start, no object is compiled.
TEST(Scenes, ACancelStopsTheObjectsCompile) {
  const SceneDesc desc =
      load_scene_file(std::string(NIMBUS_SOURCE_DIR) + "/scenes/lanterns.json", {});
  BuildMonitor stop;
  stop.cancel = [] { return true; };
  EXPECT_TRUE(compile_scene(desc, stop).objects.empty());
  BuildMonitor never;
  never.cancel = [] { return false; };
  EXPECT_EQ(compile_scene(desc, never).objects.size(), desc.objects.size());
}

}  // namespace scenes_test
}  // namespace nimbus
