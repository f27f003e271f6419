#pragma once
// The state a render adds to: per pixel, the sum of the sample values, the sum of their squares
// and the number of samples. Enough for the image and its standard error, and mergeable.
//
// Bit-identical however the work is split: the sums of sample values are exact (fixed point,
// render/exact_sum.h), so a pixel's sum, and with it its mean, is the same bits whichever
// threads, calls or processes rendered which of its samples, and in whichever order the parts
// are merged. The sums of squares, which only feed error estimates, are doubles: they are the
// same bits when each pixel's samples are added in sample order (one render, or a render that
// continues where the film left off), and agree to rounding otherwise.

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <vector>

#include "nimbus/render/aov.h"
#include "nimbus/render/exact_sum.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

// Who is using a film that must not change or be read meanwhile (FilmClaim): render_into while it
// adds samples. Of the object, not of its value: a copy starts unused, and an assignment leaves
// the target's use as it was.
class FilmUse {
 public:
  FilmUse() = default;
  FilmUse(const FilmUse&) noexcept {}
  FilmUse& operator=(const FilmUse&) noexcept { return *this; }

 private:
  friend class FilmClaim;
  std::atomic<const char*> holder_{nullptr};  // what the user is doing: "rendered into"
};

struct Film {
  int width = 0, height = 0;
  // The exact sums count in units of 2^(exponent - 64) (film_exponent): the scale of the
  // scene's light, so that radiance of any finite magnitude is summed exactly.
  int exponent = 0;
  std::vector<ExactRgb> sum;  // exact
  std::vector<Rgb> sum_sq;
  std::vector<uint32_t> samples;  // per pixel
  AovSums aov;                    // the AOVs' sums (render/aov.h), for those asked for
  FilmUse use;                    // claimed by a render (FilmClaim); not part of the value

  Film() = default;
  Film(int w, int h, int exponent_ = 0, AovSet aovs = {}, int depth_exponent = 0)
      : width(w),
        height(h),
        exponent(exponent_),
        sum(size_t(w) * h),
        sum_sq(size_t(w) * h),
        samples(size_t(w) * h, 0),
        aov(aovs, size_t(w) * h, depth_exponent) {}
  int pixels() const { return width * height; }
  // The most samples any pixel holds; 0 for a film without pixels.
  uint32_t most_samples() const {
    return samples.empty() ? 0u : *std::max_element(samples.begin(), samples.end());
  }
  // The largest magnitude a sample may have: 2^(62 + exponent) (4.6e18 at exponent 0).
  double max_value() const { return std::ldexp(kExactSumMaxValue, exponent); }
  // Adds one sample. A value that is NaN or of magnitude max_value() or more in any channel
  // never enters the sums (one such sample would poison the pixel for good): it counts as a
  // sample of value 0, so the pixel's sample count stays the number of samples rendered, and add
  // returns false so that the caller can report it. Negative values are accepted: the weighted
  // trackers are unbiased through signed weights where majorants do not bound.
  bool add(int pixel, const Rgb& value) {
    ++samples[pixel];
    const double limit = max_value();
    for (int c = 0; c < 3; ++c)
      if (!(std::abs(value[c]) < limit)) return false;
    sum[pixel] += to_fixed(value, exponent);
    sum_sq[pixel] += value * value;
    return true;
  }
  // The pixel's mean sample value; 0 for a pixel without samples.
  Rgb mean(int pixel) const {
    return samples[pixel] > 0 ? sum[pixel].value(exponent) / double(samples[pixel]) : Rgb(0.0);
  }
  // Variance of the pixel's mean estimate (sample variance / samples); 0 below 2 samples.
  Rgb variance_of_mean(int pixel) const;
};

// Holds a film for one user at a time, until it is destroyed: two renders into one film at
// once (issue 44: two threads of a Python program) would race on the sums, and the samples of
// one would be lost. `doing` says what the holder does, for the refusal of another:
// std::invalid_argument("the film is already being rendered into (on another thread): wait for
// that to end, or use another film").
class FilmClaim {
 public:
  explicit FilmClaim(Film& film, const char* doing = "rendered into");
  ~FilmClaim();
  FilmClaim(const FilmClaim&) = delete;
  FilmClaim& operator=(const FilmClaim&) = delete;

 private:
  FilmUse& use_;
};

// The film exponent for a scene whose brightest emitter has magnitude `brightest` (0 for none):
// 0, the exponent of every film before it existed, while 2^-44 <= brightest < 2^23; else
// ilogb(brightest) - 22, so that samples up to 2^40 times the brightest emitter are kept and the
// sums resolve 2^-86 of it. A scene lit at 10^19 or at 10^-20 is then summed as one lit at 1.
int film_exponent(double brightest);

// Adds `from` into `into` (films of one size, exponent and AOV layers, else
// std::invalid_argument): a pixel `into` has no samples of takes `from`'s sums as they are;
// otherwise the sums and counts are added (the exact sums exactly).
void merge(Film& into, const Film& from);

// The average of a set of pixel means and its standard error (pixels are independent).
struct MeanEstimate {
  Rgb mean;
  Rgb standard_error;
};
MeanEstimate region_mean(const Film& film, const std::vector<int>& pixels);
MeanEstimate image_mean(const Film& film);

}  // namespace nimbus
