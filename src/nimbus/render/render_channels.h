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
#include "nimbus/render/path_sampler.h"
#include "nimbus/render/path_spectra.h"
#include "nimbus/render/renderer.h"

namespace nimbus {

// Adds the samples [range.s0, range.s1) of the pixels of `range` (resolved and checked by
// render_into) to the film, each path with a fresh policy from `make_policy`.
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

  constexpr int kTile = 16;
  tbb::parallel_for(
      tbb::blocked_range2d<int>(range.y0, range.y1, kTile, range.x0, range.x1, kTile),
      [&](const tbb::blocked_range2d<int>& tile) {
        Counters& local = counters.local();
        PathSpectra<N>& ps = spectra.local();
        if (!spectral) prepare_path_spectra(ps, scene, 0.0);
        for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
          for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
            if (cancelled.load(std::memory_order_relaxed) || (options.cancel && options.cancel())) {
              cancelled = true;
              return;
            }
            const int pixel = y * W + x;
            for (int s = range.s0; s < range.s1; ++s) {
              PathSampler sampler(scene.settings, zsobol, x, y, uint64_t(pixel), uint64_t(s));
              const std::array<double, 2> u = sampler.get2d(SampleDims::kCamera);
              const Ray ray = scene.camera.generate(x + u[0], y + u[1]);
              if (spectral) prepare_path_spectra(ps, scene, sampler.get1d(SampleDims::kWavelength));
              auto policy = make_policy(sampler);
              FirstVertex first;
              const Spectrum<N> L = trace_path(scene, ps, ray, sampler, local, policy,
                                               record_first_vertex ? &first : nullptr);
              if (!film.add(pixel, to_film_rgb(L, ps.ch))) ++local.rejected_samples;
              if (record_first_vertex) film.aov.add(size_t(pixel), first);
            }
          }
        const long done = pixels_done += long(tile.rows().size()) * long(tile.cols().size());
        // A lock that a throwing callback releases too: the exception ends the render.
        if (const std::unique_lock lock(progress_mutex, std::try_to_lock);
            options.progress && lock.owns_lock())
          options.progress(double(done) / range_pixels);
      });

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
