#include "nimbus/render/renderer.h"

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <stdexcept>
#include <string>

namespace nimbus {

// Instantiated in generated translation units (CMakeLists.txt, render_channels.cpp.in).
template <int N>
RenderResult render_channels(const Scene& scene, const RenderOptions& options, int threads);

namespace {

template <int N>
RenderResult dispatch(const Scene& scene, const RenderOptions& options, int threads, int n) {
  if constexpr (N > kMaxWavelengths) {
    throw std::invalid_argument("spectral mode: " + std::to_string(n) + " wavelengths");
  } else {
    if (n == N) return render_channels<N>(scene, options, threads);
    return dispatch<N + 1>(scene, options, threads, n);
  }
}

}  // namespace

RenderResult render(const Scene& scene, const RenderOptions& options) {
  const int threads = options.threads > 0 ? options.threads : tbb::info::default_concurrency();
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  if (scene.settings.spectral.mode == SpectralSettings::Mode::Rgb)
    return render_channels<3>(scene, options, threads);
  const int n = scene.settings.spectral.wavelengths;
  if (n < kMinWavelengths || n > kMaxWavelengths)
    throw std::invalid_argument("spectral mode needs " + std::to_string(kMinWavelengths) + " to " +
                                std::to_string(kMaxWavelengths) + " wavelengths, not " +
                                std::to_string(n));
  return dispatch<kMinWavelengths>(scene, options, threads, n);
}

}  // namespace nimbus
