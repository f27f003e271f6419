#include "nimbus/render/renderer.h"

#include <fmt/format.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <stdexcept>
#include <string>

#include "nimbus/render/noise_target.h"
#include "nimbus/render/wavelength_counts.h"

namespace nimbus {

// Instantiated in generated translation units (CMakeLists.txt, render_channels.cpp.in).
template <int N>
RenderStats render_channels(const Scene& scene, Film& film, const RenderRange& range,
                            const RenderOptions& options, int threads);

namespace {

// With a noise target: the range covers whole blocks, whose samples start at 0 (their
// decisions read every sample), and each block holds range.s0 samples or is done with fewer.
RenderRange resolve_blocks(const NoiseRule& rule, const Film& film, const RenderRange& r) {
  const int W = film.width, H = film.height;
  if (!film.aov.layers.has(Aov::Half))
    throw std::invalid_argument(
        "with a noise target, the film must hold the half sums its error is estimated from: a "
        "film made for the scene (make_film)");
  const auto edge = [](int v, int size) { return v % kNoiseBlock == 0 || v == size; };
  if (r.x0 % kNoiseBlock != 0 || r.y0 % kNoiseBlock != 0 || !edge(r.x1, W) || !edge(r.y1, H))
    throw std::invalid_argument(fmt::format(
        "with a noise target, pixels [{}, {}) x [{}, {}) must cover whole {}x{} blocks (starting "
        "at multiples of {})",
        r.x0, r.x1, r.y0, r.y1, kNoiseBlock, kNoiseBlock, kNoiseBlock));
  if (r.s1 > rule.cap)
    throw std::invalid_argument(fmt::format(
        "with a noise target, samples [{}, {}) go past the spp, {}", r.s0, r.s1, rule.cap));
  for (int by = r.y0 / kNoiseBlock; by * kNoiseBlock < r.y1; ++by)
    for (int bx = r.x0 / kNoiseBlock; bx * kNoiseBlock < r.x1; ++bx) {
      const NoiseBlock b = noise_block(film, bx, by);
      const uint32_t held = film.samples[size_t(b.y0) * W + b.x0];
      for (int y = b.y0; y < b.y1; ++y)
        for (int x = b.x0; x < b.x1; ++x)
          if (film.samples[size_t(y) * W + x] != held)
            throw std::invalid_argument(fmt::format(
                "with a noise target, the pixels of the block at ({}, {}) must hold one count: "
                "({}, {}) holds {}, ({}, {}) {}",
                b.x0, b.y0, b.x0, b.y0, held, x, y, film.samples[size_t(y) * W + x]));
      if (held == uint32_t(r.s0) || (held < uint32_t(r.s0) && block_done(rule, film, b))) continue;
      throw std::invalid_argument(fmt::format(
          "with a noise target, the block at ({}, {}) holds {} samples; samples [{}, {}) continue "
          "from {} (or from fewer, where the block is done)",
          b.x0, b.y0, held, r.s0, r.s1, r.s0));
    }
  return r;
}

// The range with its open ends resolved, checked against the film.
RenderRange resolve(const Scene& scene, const Film& film, RenderRange r) {
  const int W = scene.settings.width, H = scene.settings.height;
  if (film.width != W || film.height != H)
    throw std::invalid_argument(fmt::format("the film is {}x{} pixels, the scene's image {}x{}",
                                            film.width, film.height, W, H));
  if (scene.surfaces.object_count != scene.objects.size() ||
      scene.surfaces.light_count != scene.lights.size())
    throw std::invalid_argument(
        "the scene's objects or lights changed since finish_scene: call it again");
  if (film.exponent != scene.film_exponent)
    throw std::invalid_argument(
        fmt::format("the film's exponent is {}, the scene's {}: a film made for another scene's "
                    "light (make_film)",
                    film.exponent, scene.film_exponent));
  if (film.aov.layers.has(Aov::Depth) && film.aov.depth_exponent != depth_exponent(scene))
    throw std::invalid_argument(fmt::format(
        "the film's depths are summed in units of 2^{}, the scene's in 2^{}: a film made for "
        "another scene (make_film)",
        film.aov.depth_exponent - kExactSumFractionBits,
        depth_exponent(scene) - kExactSumFractionBits));
  if (r.x1 < 0) r.x1 = W;
  if (r.y1 < 0) r.y1 = H;
  if (r.s1 < 0) r.s1 = scene.settings.spp;
  if (r.x0 < 0 || r.y0 < 0 || r.x0 > r.x1 || r.y0 > r.y1 || r.x1 > W || r.y1 > H)
    throw std::invalid_argument(fmt::format("pixels [{}, {}) x [{}, {}) are not within {}x{}", r.x0,
                                            r.x1, r.y0, r.y1, W, H));
  if (r.s0 < 0 || r.s0 > r.s1)
    throw std::invalid_argument(fmt::format("samples [{}, {}) are not a range", r.s0, r.s1));
  const NoiseRule rule = noise_rule(scene.settings);
  if (rule.on()) return resolve_blocks(rule, film, r);
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x)
      if (const uint32_t held = film.samples[size_t(y) * W + x];
          held != 0 && held != uint32_t(r.s0))
        throw std::invalid_argument(
            fmt::format("pixel ({}, {}) holds {} samples; samples [{}, {}) continue from {}", x, y,
                        film.samples[size_t(y) * W + x], r.s0, r.s1, r.s0));
  return r;
}

}  // namespace

RenderStats render_into(const Scene& scene, Film& film, const RenderOptions& options) {
  const FilmClaim claim(film);  // before the checks, which read the pixels another render adds to
  const RenderRange range = resolve(scene, film, options.range);
  const int threads = options.threads > 0 ? options.threads : tbb::info::default_concurrency();
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  if (scene.settings.spectral.mode == SpectralSettings::Mode::Rgb)
    return render_channels<3>(scene, film, range, options, threads);
  return render_spectral(scene.settings.spectral.wavelengths, scene, film, range, options, threads);
}

RenderResult render(const Scene& scene, const RenderOptions& options) {
  RenderResult result;
  result.film = make_film(scene);
  const RenderStats s = render_into(scene, result.film, options);
  result.counters = s.counters;
  result.seconds = s.seconds;
  result.threads = s.threads;
  result.cancelled = s.cancelled;
  return result;
}

}  // namespace nimbus
