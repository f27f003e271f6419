#pragma once
// The render loop for one channel count N (3: rgb mode; kMinWavelengths..kMaxWavelengths:
// spectral mode), instantiated once per N in its own translation unit
// (render/render_channels.cpp.in) so the instantiations build in parallel; renderer.cpp
// dispatches once per render.

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <mutex>

#include "nimbus/render/integrator.h"
#include "nimbus/render/path_spectra.h"
#include "nimbus/render/renderer.h"

namespace nimbus {

template <int N>
RenderResult render_channels(const Scene& scene, const RenderOptions& options, int threads) {
  const int W = scene.settings.width, H = scene.settings.height, spp = scene.settings.spp;
  RenderResult result{Film(W, H), {}, 0, threads};
  result.film.spp = spp;
  tbb::enumerable_thread_specific<Counters> counters;
  tbb::enumerable_thread_specific<PathSpectra<N>> spectra;
  const bool spectral = scene.settings.spectral.mode == SpectralSettings::Mode::Spectral;
  std::atomic<long> pixels_done{0};
  std::mutex progress_mutex;
  const auto start = std::chrono::steady_clock::now();

  constexpr int kTile = 16;
  tbb::parallel_for(
      tbb::blocked_range2d<int>(0, H, kTile, 0, W, kTile),
      [&](const tbb::blocked_range2d<int>& tile) {
        Counters& local = counters.local();
        PathSpectra<N>& ps = spectra.local();
        if (!spectral) prepare_path_spectra(ps, scene, 0.0);
        for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
          for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
            const int pixel = y * W + x;
            for (int s = 0; s < spp; ++s) {
              Rng rng = Rng::for_sample(scene.settings.seed, uint64_t(pixel), uint64_t(s));
              const double u1 = rng.uniform(), u2 = rng.uniform();
              const Ray ray = scene.camera.generate(x + u1, y + u2);
              if (spectral) prepare_path_spectra(ps, scene, rng.uniform());
              const Spectrum<N> L = radiance(scene, ps, ray, rng, local);
              result.film.add(pixel, to_film_rgb(L, ps.ch));
            }
          }
        const long done = pixels_done += long(tile.rows().size()) * long(tile.cols().size());
        if (options.progress && progress_mutex.try_lock()) {
          options.progress(double(done) / (double(W) * H));
          progress_mutex.unlock();
        }
      });

  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (const Counters& c : counters) result.counters += c;
  return result;
}

}  // namespace nimbus
