#pragma once
// AOVs (arbitrary output variables): per-pixel layers written beside the colour, for denoisers
// such as OIDN (docs/denoising.md). Albedo, normal and depth come from what each camera path met
// first (FirstVertex, recorded by trace_path) and are averaged over the pixel's samples as the
// colour is; variance is the colour's own variance of the mean (Film::variance_of_mean); samples
// is each pixel's sample count (a render to a noise target gives pixels different counts).
//
// One more layer is recorded but never written: Half, the sum of the odd samples, which a render
// to a noise target estimates its error from (render/noise_target.h).
//
// The sums are exact, as the colour's (render/exact_sum.h): a film's layers are the same bits
// however its samples were split between threads, calls or processes and merged.

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <vector>

#include "nimbus/math/vec3.h"
#include "nimbus/render/exact_sum.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

// In the order of an image's layers (io/film_image.h) and of the docs; names in
// render/setting_names.h.
enum class Aov : uint8_t { Albedo, Normal, Depth, Variance, Samples, Half };
// The layers an image can have, in order; Half is the film's alone.
inline constexpr Aov kAllAovs[] = {Aov::Albedo, Aov::Normal, Aov::Depth, Aov::Variance,
                                   Aov::Samples};

class AovSet {
 public:
  constexpr AovSet() = default;
  constexpr AovSet(std::initializer_list<Aov> aovs) {
    for (Aov a : aovs) add(a);
  }
  constexpr bool has(Aov a) const { return (bits_ >> int(a)) & 1; }
  constexpr void add(Aov a) { bits_ = uint8_t(bits_ | 1u << int(a)); }
  constexpr bool empty() const { return bits_ == 0; }
  constexpr uint8_t bits() const { return bits_; }
  static constexpr AovSet from_bits(uint8_t bits) {
    AovSet s;
    s.bits_ = bits;
    return s;
  }
  // The AOVs whose sums a film holds: all but variance and samples, which the colour's sums and
  // counts give.
  constexpr AovSet recorded() const {
    return from_bits(uint8_t(bits_ & (1u << int(Aov::Albedo) | 1u << int(Aov::Normal) |
                                      1u << int(Aov::Depth) | 1u << int(Aov::Half))));
  }
  bool operator==(const AovSet&) const = default;

 private:
  uint8_t bits_ = 0;
};

// What a camera path met first, for the AOVs. Albedo and normal are those of its first vertex
// that is not a perfect specular surface (OIDN's advice for delta surfaces); depth is where the
// camera ray itself ends. docs/cli.md states each case.
struct FirstVertex {
  Rgb albedo{0.0};
  Vec3 normal;  // unit, facing the ray that met the vertex; 0 for a ray that escaped
  // Along the camera ray (of unit direction); infinity: it met nothing.
  double depth = std::numeric_limits<double>::infinity();
};

// The per-pixel sums of a film's recorded AOVs (albedo, normal, depth, half), allocated only for
// those asked for.
struct AovSums {
  AovSet layers;  // recorded AOVs only
  // Depths are summed in units of 2^(depth_exponent - 64), an exponent on the scale of the
  // scene (depth_exponent in render/scene.h), so that scenes of any size resolve them.
  int depth_exponent = 0;
  std::vector<ExactRgb> albedo, normal;
  std::vector<int128> depth;
  std::vector<uint32_t> depth_samples;  // samples whose camera ray met something
  // Half: the odd samples (in_half, render/noise_target.h), summed again exactly in the film's
  // units (Film::exponent).
  std::vector<ExactRgb> half;

  AovSums() = default;
  AovSums(AovSet aovs, size_t pixels, int depth_exponent_);

  // Adds one sample's first vertex to the pixel (of which Film::add counts the sample). A depth
  // of magnitude 2^(62 + depth_exponent) or more counts as meeting nothing.
  void add(size_t pixel, const FirstVertex& v);
  // Adds pixel `from_pixel` of `from` (of the same layers and exponent) to `pixel`.
  void add(size_t pixel, const AovSums& from, size_t from_pixel);
  void clear(size_t pixel);

  // The pixel's means over its `samples` samples: 0 without samples; depth over the samples
  // that met something, infinity if none did.
  Rgb albedo_mean(size_t pixel, uint32_t samples) const;
  Vec3 normal_mean(size_t pixel, uint32_t samples) const;
  double depth_mean(size_t pixel) const;

  // Calls f on each per-pixel vector held, in a fixed order: how files and messages carry them.
  template <class F>
  void for_each_vector(F&& f) {
    each_vector(*this, f);
  }
  template <class F>
  void for_each_vector(F&& f) const {
    each_vector(*this, f);
  }

 private:
  template <class Self, class F>
  static void each_vector(Self& s, F& f) {
    if (s.layers.has(Aov::Albedo)) f(s.albedo);
    if (s.layers.has(Aov::Normal)) f(s.normal);
    if (s.layers.has(Aov::Depth)) {
      f(s.depth);
      f(s.depth_samples);
    }
    if (s.layers.has(Aov::Half)) f(s.half);
  }
};

// Bytes per pixel that a film's sums of `aovs` take.
size_t aov_film_bytes(AovSet aovs);
// Floats per pixel that an image's layers of `aovs` take.
int aov_image_floats(AovSet aovs);

}  // namespace nimbus
