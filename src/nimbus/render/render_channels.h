#pragma once
// The render loop for one channel count N (3: rgb mode; the built wavelength counts: spectral
// mode), instantiated once per N in its own translation unit (render/render_channels.cpp.in) so
// the instantiations build in parallel; renderer.cpp dispatches once per render
// (wavelength_counts.h).

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <mutex>

#include "nimbus/math/zsobol.h"
#include "nimbus/render/integrator.h"
#include "nimbus/render/noise_target.h"
#include "nimbus/render/path_sampler.h"
#include "nimbus/render/path_spectra.h"
#include "nimbus/render/renderer.h"

namespace nimbus {

// Adds the samples [range.s0, range.s1) of the pixels of `range` (resolved and checked by
// render_into) to the film, each path with a fresh policy from `make_policy`; with a noise
// target, each block's only until it is done (render/noise_target.h).
template <int N, class MakePolicy>
RenderStats render_tiles(const Scene& scene, Film& film, const RenderRange& range,
                         const RenderOptions& options, int threads, const MakePolicy& make_policy) {
  const int W = scene.settings.width;
  RenderStats stats;
  stats.threads = threads;
  tbb::enumerable_thread_specific<Counters> counters;
  tbb::enumerable_thread_specific<PathSpectra<N>> spectra;
  const bool spectral = scene.settings.spectral.mode == SpectralSettings::Mode::Spectral;
  const double range_pixels = double(range.x1 - range.x0) * double(range.y1 - range.y0);
  std::atomic<long> pixels_done{0};
  std::atomic<bool> cancelled{false};
  std::mutex progress_mutex;
  const auto start = std::chrono::steady_clock::now();
  const ZSobol zsobol(W, scene.settings.height, scene.settings.seed);
  // The first vertex is recorded only into a film that holds AOV sums (render/aov.h).
  const bool record_first_vertex = !film.aov.layers.empty();

  const bool record_half = film.aov.layers.has(Aov::Half);
  const auto cancel_now = [&] {
    if (cancelled.load(std::memory_order_relaxed) || (options.cancel && options.cancel()))
      cancelled = true;
    return cancelled.load(std::memory_order_relaxed);
  };
  // Samples [s0, s1) of pixel (x, y).
  const auto sample_pixel = [&](int x, int y, int s0, int s1, Counters& local, PathSpectra<N>& ps) {
    const int pixel = y * W + x;
    for (int s = s0; s < s1; ++s) {
      PathSampler sampler(scene.settings, zsobol, x, y, uint64_t(pixel), uint64_t(s));
      const std::array<double, 2> u = sampler.get2d(SampleDims::kCamera);
      const Ray ray = scene.camera.generate(x + u[0], y + u[1]);
      if (spectral) prepare_path_spectra(ps, scene, sampler.get1d(SampleDims::kWavelength));
      auto policy = make_policy(sampler);
      FirstVertex first;
      const Spectrum<N> L = trace_path(scene, ps, ray, sampler, local, policy,
                                       record_first_vertex ? &first : nullptr);
      const Rgb value = to_film_rgb(L, ps.ch);
      if (!film.add(pixel, value))
        ++local.rejected_samples;
      else if (record_half && in_half(uint64_t(s)))
        film.aov.half[size_t(pixel)] += to_fixed(value, film.exponent);
      if (record_first_vertex) film.aov.add(size_t(pixel), first);
    }
  };
  // A lock that a throwing callback releases too: the exception ends the render.
  const auto report = [&](long done) {
    if (const std::unique_lock lock(progress_mutex, std::try_to_lock);
        options.progress && lock.owns_lock())
      options.progress(double(done) / range_pixels);
  };

  const NoiseRule rule = noise_rule(scene.settings);
  if (rule.on()) {
    // Block by block (resolve_blocks checked that the range covers whole ones): each takes its
    // samples a pass at a time and is decided at each pass end (render/noise_target.h).
    const int bx0 = range.x0 / kNoiseBlock, by0 = range.y0 / kNoiseBlock;
    const int bx1 = noise_blocks_across(range.x1), by1 = noise_blocks_across(range.y1);
    tbb::parallel_for(tbb::blocked_range2d<int>(by0, by1, 2, bx0, bx1, 2),
                      [&](const tbb::blocked_range2d<int>& blocks) {
                        Counters& local = counters.local();
                        PathSpectra<N>& ps = spectra.local();
                        if (!spectral) prepare_path_spectra(ps, scene, 0.0);
                        for (int by = blocks.rows().begin(); by < blocks.rows().end(); ++by)
                          for (int bx = blocks.cols().begin(); bx < blocks.cols().end(); ++bx) {
                            const NoiseBlock b = noise_block(film, bx, by);
                            int n = int(film.samples[size_t(b.y0) * W + b.x0]);
                            if (n < range.s0) n = range.s1;  // done with fewer (resolve_blocks)
                            while (n < range.s1 && !block_done(rule, film, b)) {
                              if (cancel_now()) return;
                              const int end = std::min(range.s1, next_pass_end(rule, n));
                              for (int y = b.y0; y < b.y1; ++y)
                                for (int x = b.x0; x < b.x1; ++x)
                                  sample_pixel(x, y, n, end, local, ps);
                              n = end;
                            }
                            report(pixels_done += long(b.x1 - b.x0) * long(b.y1 - b.y0));
                          }
                      });
  } else {
    constexpr int kTile = 16;
    tbb::parallel_for(
        tbb::blocked_range2d<int>(range.y0, range.y1, kTile, range.x0, range.x1, kTile),
        [&](const tbb::blocked_range2d<int>& tile) {
          Counters& local = counters.local();
          PathSpectra<N>& ps = spectra.local();
          if (!spectral) prepare_path_spectra(ps, scene, 0.0);
          for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
            for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
              if (cancel_now()) return;
              sample_pixel(x, y, range.s0, range.s1, local, ps);
            }
          report(pixels_done += long(tile.rows().size()) * long(tile.cols().size()));
        });
  }

  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (const Counters& c : counters) stats.counters += c;
  stats.cancelled = cancelled;
  return stats;
}

// render_tiles with the policy of the scene's tracking mode, resolved once (with_tracking_policy).
template <int N>
RenderStats render_channels(const Scene& scene, Film& film, const RenderRange& range,
                            const RenderOptions& options, int threads) {
  return with_tracking_policy<N>(scene.settings.tracking, [&](const auto& make_policy) {
    return render_tiles<N>(scene, film, range, options, threads, make_policy);
  });
}

}  // namespace nimbus
