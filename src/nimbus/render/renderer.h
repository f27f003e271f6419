#pragma once
// Renders a compiled scene over tiles in parallel (oneTBB). Each pixel sample draws from its own
// random stream keyed by (seed, pixel, sample index) and the film's sums are exact, so the image
// is bit-identical for any thread count and any split of the pixels or of the samples between
// renders, merged in any order (render/film.h).

#include <functional>

#include "nimbus/render/counters.h"
#include "nimbus/render/film.h"
#include "nimbus/render/scene.h"

namespace nimbus {

// The part of the work a render does: the pixels [x0, x1) × [y0, y1) and, for each, the samples
// with indices [s0, s1). An end of -1 means the film's edge (x1, y1) or the scene's spp (s1).
struct RenderRange {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  int s0 = 0, s1 = -1;
};

struct RenderOptions {
  int threads = 0;  // 0: all hardware threads
  // Called now and then with the fraction of the range done, from one thread at a time.
  std::function<void(double)> progress;
  RenderRange range;
  // Polled before each pixel, possibly from several threads at once; once it returns true no
  // pixel starts: every pixel then holds either all of the range's samples or none of them.
  std::function<bool()> cancel;
};

struct RenderStats {
  Counters counters;
  double seconds = 0;
  int threads = 0;
  bool cancelled = false;
};

// Adds the samples of options.range to `film`, which must have the scene's size; each pixel of
// the range must hold either no samples (a film may start at any sample index, e.g. one of
// several processes sharing a pixel's samples) or exactly range.s0 (it continues where it left
// off); else std::invalid_argument, naming the pixel. The film is claimed meanwhile (FilmClaim in
// render/film.h): a second render into it at the same time is std::invalid_argument.
RenderStats render_into(const Scene& scene, Film& film, const RenderOptions& options = {});

struct RenderResult {
  Film film;
  Counters counters;
  double seconds = 0;
  int threads = 0;
  bool cancelled = false;
};

// render_into a fresh film.
RenderResult render(const Scene& scene, const RenderOptions& options = {});

}  // namespace nimbus
