#include "nimbus/render/film.h"

#include <fmt/format.h>

#include <cmath>
#include <numeric>
#include <stdexcept>

namespace nimbus {

Rgb Film::variance_of_mean(int pixel) const {
  const double n = samples[pixel];
  if (n < 2) return Rgb(0.0);
  const Rgb m = mean(pixel);
  Rgb var = (sum_sq[pixel] / n - m * m) * (n / (n - 1));
  for (int c = 0; c < 3; ++c) var[c] = std::max(0.0, var[c]);
  return var / n;
}

FilmClaim::FilmClaim(Film& film, const char* doing) : use_(film.use) {
  const char* free = nullptr;
  if (!use_.holder_.compare_exchange_strong(free, doing, std::memory_order_acquire))
    throw std::invalid_argument(
        fmt::format("the film is already being {} (on another thread): wait for that to end, or "
                    "use another film",
                    free));
}

FilmClaim::~FilmClaim() {
  use_.holder_.store(nullptr, std::memory_order_release);
}

int film_exponent(double brightest) {
  if (!(brightest > 0) || !std::isfinite(brightest)) return 0;
  const int e = std::ilogb(brightest);
  return e >= -44 && e <= 22 ? 0 : e - 22;
}

void merge(Film& into, const Film& from) {
  if (into.width != from.width || into.height != from.height)
    throw std::invalid_argument(fmt::format("merging films of {}x{} and {}x{} pixels", into.width,
                                            into.height, from.width, from.height));
  if (into.exponent != from.exponent)
    throw std::invalid_argument(
        fmt::format("merging films of exponents {} and {}", into.exponent, from.exponent));
  if (into.aov.layers != from.aov.layers || into.aov.depth_exponent != from.aov.depth_exponent)
    throw std::invalid_argument("merging films of different AOV layers");
  for (int p = 0; p < into.pixels(); ++p) {
    if (from.samples[p] == 0) continue;
    if (into.samples[p] == 0) {
      into.sum[p] = from.sum[p];
      into.sum_sq[p] = from.sum_sq[p];
    } else {
      into.sum[p] += from.sum[p];
      into.sum_sq[p] += from.sum_sq[p];
    }
    into.aov.add(size_t(p), from.aov, size_t(p));
    into.samples[p] += from.samples[p];
  }
}

MeanEstimate region_mean(const Film& film, const std::vector<int>& pixels) {
  Rgb mean(0.0), var(0.0);
  for (int p : pixels) {
    mean += film.mean(p);
    var += film.variance_of_mean(p);
  }
  const double n = static_cast<double>(pixels.size());
  MeanEstimate e{mean / n, Rgb(0.0)};
  for (int c = 0; c < 3; ++c) e.standard_error[c] = std::sqrt(var[c]) / n;
  return e;
}

MeanEstimate image_mean(const Film& film) {
  std::vector<int> all(size_t(film.width) * film.height);
  std::iota(all.begin(), all.end(), 0);
  return region_mean(film, all);
}

}  // namespace nimbus
