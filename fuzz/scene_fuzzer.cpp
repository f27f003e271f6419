// libFuzzer target (docs/testing.md, "Fuzzing"): a scene file's text is loaded, compiled and
// rendered as a tiny image. A SceneError is the expected answer to bad input; any other
// exception, a crash, a sanitizer report, a hang or a non-finite pixel is a finding.

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "nimbus/nimbus.h"

namespace {

constexpr std::size_t kMaxFuzzQuadrics = 1000;

// Keeps one input's work small: what is fuzzed is the loader and the code paths, not the cost of
// large images, deep paths or fine octrees (each of which the CLI bounds or estimates).
void make_small(nimbus::SceneDesc& desc) {
  desc.settings.width = std::min(desc.settings.width, 6);
  desc.settings.height = std::min(desc.settings.height, 4);
  desc.settings.spp = 1;
  desc.settings.max_depth = std::min(desc.settings.max_depth, 6);
  nimbus::TrackingSettings& t = desc.settings.tracking;
  t.octree_depth = std::min(t.octree_depth, 3);
  t.majorant_samples = std::min(t.majorant_samples, 16);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  nimbus::SceneDesc desc;
  try {
    desc = nimbus::load_scene_text(text, "fuzz.json");
  } catch (const nimbus::SceneError&) {
    return 0;
  }
  // Shapes cost time in proportion to their quadrics, up to the loader's limit (8 192 coincident
  // spheres take 9 s, longer under the sanitizers): that is cost, not a bug, so the fuzzer
  // leaves large shapes to the loader's test.
  for (const nimbus::ObjectDesc& o : desc.objects)
    if (nimbus::count_quadrics(*o.shape, kMaxFuzzQuadrics) > kMaxFuzzQuadrics) return 0;
  make_small(desc);
  try {
    const nimbus::Scene scene = nimbus::compile_scene(desc);
    nimbus::RenderOptions options;
    options.threads = 1;
    const nimbus::RenderResult result = nimbus::render(scene, options);
    for (int p = 0; p < result.film.pixels(); ++p) {
      const nimbus::Rgb mean = result.film.mean(p);
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(mean[c])) {
          std::fprintf(stderr, "fuzz: pixel %d is not finite\n", p);
          std::abort();
        }
    }
  } catch (const nimbus::SceneError&) {
    return 0;  // compile-time checks (e.g. a shape without finite bounds) name the JSON path
  }
  return 0;
}
