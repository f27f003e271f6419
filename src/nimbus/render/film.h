#pragma once
// Per-pixel sums and sums of squares of the sample values: mergeable (threads, processes) and
// enough for the image and its standard error.

#include <vector>

#include "nimbus/io/image.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

struct Film {
  int width = 0, height = 0;
  long spp = 0;  // samples per pixel, the same for every pixel
  std::vector<Rgb> sum, sum_sq;

  Film(int w, int h) : width(w), height(h), sum(size_t(w) * h), sum_sq(size_t(w) * h) {}
  void add(int pixel, const Rgb& value) {
    sum[pixel] += value;
    sum_sq[pixel] += value * value;
  }
  Rgb mean(int pixel) const { return sum[pixel] / double(spp); }
  // Variance of the pixel's mean estimate (sample variance / spp).
  Rgb variance_of_mean(int pixel) const;
};

Image to_image(const Film& film);

// The average of a set of pixel means and its standard error (pixels are independent).
struct MeanEstimate {
  Rgb mean;
  Rgb standard_error;
};
MeanEstimate region_mean(const Film& film, const std::vector<int>& pixels);
MeanEstimate image_mean(const Film& film);

}  // namespace nimbus
