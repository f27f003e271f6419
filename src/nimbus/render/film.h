#pragma once
// The state a render adds to: per pixel, the sum of the sample values, the sum of their squares
// and the number of samples. Enough for the image and its standard error, and mergeable.
//
// Bit-identical however the work is split: each pixel's samples are added in sample order, so a
// pixel's sums are the same bits whichever thread, call or process rendered it, as long as its
// samples arrive in order. Pixels may be split between renders freely (merge takes a pixel that
// the film has no samples of as it is), and a render may continue a pixel's samples where the
// film left off (render_into checks that it does). Two films holding different samples of the
// same pixel merge by adding their sums: the same expectation, not the same bits.

#include <cmath>
#include <cstdint>
#include <vector>

#include "nimbus/spectral/spectrum.h"

namespace nimbus {

struct Film {
  int width = 0, height = 0;
  std::vector<Rgb> sum, sum_sq;
  std::vector<uint32_t> samples;  // per pixel

  Film() = default;
  Film(int w, int h)
      : width(w), height(h), sum(size_t(w) * h), sum_sq(size_t(w) * h), samples(size_t(w) * h, 0) {}
  int pixels() const { return width * height; }
  // Adds one sample. A value that is NaN or infinite in any channel, or whose square is not
  // finite, never enters the sums (one such sample would poison the pixel for good): it counts
  // as a sample of value 0, so the pixel's sample count stays the number of samples rendered,
  // and add returns false so that the caller can report it. Negative values are accepted: the
  // weighted trackers are unbiased through signed weights where majorants do not bound.
  bool add(int pixel, const Rgb& value) {
    ++samples[pixel];
    const Rgb sq = value * value;
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(sq[c])) return false;
    sum[pixel] += value;
    sum_sq[pixel] += sq;
    return true;
  }
  // The pixel's mean sample value; 0 for a pixel without samples.
  Rgb mean(int pixel) const {
    return samples[pixel] > 0 ? sum[pixel] / double(samples[pixel]) : Rgb(0.0);
  }
  // Variance of the pixel's mean estimate (sample variance / samples); 0 below 2 samples.
  Rgb variance_of_mean(int pixel) const;
};

// Adds `from` into `into` (films of one size, else std::invalid_argument): a pixel `into` has no
// samples of takes `from`'s sums as they are; otherwise the sums and counts are added.
void merge(Film& into, const Film& from);

// The average of a set of pixel means and its standard error (pixels are independent).
struct MeanEstimate {
  Rgb mean;
  Rgb standard_error;
};
MeanEstimate region_mean(const Film& film, const std::vector<int>& pixels);
MeanEstimate image_mean(const Film& film);

}  // namespace nimbus
