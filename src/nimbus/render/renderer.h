#pragma once
// Renders a compiled scene over tiles in parallel (oneTBB). Each pixel sample draws from its own
// random stream keyed by (seed, pixel, sample index) and each pixel is summed in sample order, so
// the image is bit-identical for any thread count.

#include <functional>

#include "nimbus/render/counters.h"
#include "nimbus/render/film.h"
#include "nimbus/render/scene.h"

namespace nimbus {

struct RenderOptions {
  int threads = 0;  // 0: all hardware threads
  // Called now and then with the fraction done, from one thread at a time.
  std::function<void(double)> progress;
};

struct RenderResult {
  Film film;
  Counters counters;
  double seconds = 0;
  int threads = 0;
};

RenderResult render(const Scene& scene, const RenderOptions& options = {});

}  // namespace nimbus
