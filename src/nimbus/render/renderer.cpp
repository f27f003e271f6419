#include "nimbus/render/renderer.h"

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <mutex>

#include "nimbus/render/integrator.h"

namespace nimbus {

RenderResult render(const Scene& scene, const RenderOptions& options) {
  const int W = scene.settings.width, H = scene.settings.height, spp = scene.settings.spp;
  const int threads = options.threads > 0 ? options.threads : tbb::info::default_concurrency();
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);

  RenderResult result{Film(W, H), {}, 0, threads};
  result.film.spp = spp;
  tbb::enumerable_thread_specific<Counters> counters;
  std::atomic<long> pixels_done{0};
  std::mutex progress_mutex;
  const auto start = std::chrono::steady_clock::now();

  constexpr int kTile = 16;
  tbb::parallel_for(
      tbb::blocked_range2d<int>(0, H, kTile, 0, W, kTile),
      [&](const tbb::blocked_range2d<int>& tile) {
        Counters& local = counters.local();
        for (int y = tile.rows().begin(); y < tile.rows().end(); ++y)
          for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
            const int pixel = y * W + x;
            for (int s = 0; s < spp; ++s) {
              Rng rng = Rng::for_sample(scene.settings.seed, uint64_t(pixel), uint64_t(s));
              const double u1 = rng.uniform(), u2 = rng.uniform();
              const Ray ray = scene.camera.generate(x + u1, y + u2);
              result.film.add(pixel, radiance(scene, ray, rng, local));
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
