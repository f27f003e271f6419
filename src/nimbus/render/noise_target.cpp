#include "nimbus/render/noise_target.h"

#include <algorithm>
#include <cmath>

#include "nimbus/render/scene.h"

namespace nimbus {

NoiseRule noise_rule(const RenderSettings& settings) {
  return {settings.noise_target, settings.noise_min_spp, settings.spp};
}

namespace {

int first_pass_end(const NoiseRule& rule) {
  return std::max(2, (rule.min_spp + 1) / 2 * 2);
}

}  // namespace

int next_pass_end(const NoiseRule& rule, int n) {
  const int n0 = first_pass_end(rule);
  int end = n0;
  while (end <= n) end += std::max(n0, 2 * (end / 8));
  return std::min(end, rule.cap);
}

bool is_pass_end(const NoiseRule& rule, int n) {
  return n == rule.cap || (n > 0 && n < rule.cap && next_pass_end(rule, n - 1) == n);
}

NoiseBlock noise_block(const Film& film, int bx, int by) {
  return {bx * kNoiseBlock, by * kNoiseBlock, std::min(film.width, (bx + 1) * kNoiseBlock),
          std::min(film.height, (by + 1) * kNoiseBlock)};
}

double block_error(const Film& film, const NoiseBlock& b) {
  double sum = 0;
  int terms = 0;
  for (int y = b.y0; y < b.y1; ++y)
    for (int x = b.x0; x < b.x1; ++x) {
      const size_t p = size_t(y) * film.width + x;
      const double n = film.samples[p];
      for (int c = 0; c < 3; ++c) {
        // d/2 = (2H − S)/n, exactly up to the last rounding.
        const double half_d =
            from_fixed(2 * film.aov.half[p].c[c] - film.sum[p].c[c], film.exponent) / n;
        const double m =
            std::max(std::abs(from_fixed(film.sum[p].c[c], film.exponent) / n), kNoiseFloor);
        sum += half_d * half_d / (m * m);
        ++terms;
      }
    }
  return std::sqrt(sum / terms);
}

bool block_done(const NoiseRule& rule, const Film& film, const NoiseBlock& b) {
  const int n = int(film.samples[size_t(b.y0) * film.width + b.x0]);
  if (n >= rule.cap) return true;
  return n > 0 && is_pass_end(rule, n) && block_error(film, b) <= rule.target;
}

NoiseProgress noise_progress(const NoiseRule& rule, const Film& film) {
  double done_pixels = 0, capped_pixels = 0, held = 0, needed = 0;
  for (int by = 0; by * kNoiseBlock < film.height; ++by)
    for (int bx = 0; bx * kNoiseBlock < film.width; ++bx) {
      const NoiseBlock b = noise_block(film, bx, by);
      const double pixels = double(b.x1 - b.x0) * (b.y1 - b.y0);
      const int n = int(film.samples[size_t(b.y0) * film.width + b.x0]);
      held += pixels * n;
      if (block_done(rule, film, b)) {
        done_pixels += pixels;
        if (n >= 2 && n % 2 == 0 && block_error(film, b) > rule.target) capped_pixels += pixels;
        needed += pixels * n;
        continue;
      }
      // Without an estimate yet (fewer than 2 samples, or mid-pass with an odd count): the cap.
      double need = rule.cap;
      if (n >= 2 && n % 2 == 0) {
        const double e = block_error(film, b);
        need = std::clamp(n * (e / rule.target) * (e / rule.target), double(next_pass_end(rule, n)),
                          double(rule.cap));
      }
      needed += pixels * need;
    }
  const double pixels = double(film.width) * film.height;
  if (!(pixels > 0)) return {1.0, 0.0, 1.0};
  return {done_pixels / pixels, capped_pixels / pixels, needed > 0 ? held / needed : 1.0};
}

}  // namespace nimbus
