#include "nimbus/render/aov.h"

#include <cmath>
#include <type_traits>

#include "nimbus/math/constants.h"

namespace nimbus {

AovSums::AovSums(AovSet aovs, size_t pixels, int depth_exponent_)
    : layers(aovs.recorded()), depth_exponent(depth_exponent_) {
  for_each_vector([&](auto& v) { v.resize(pixels); });
}

void AovSums::add(size_t pixel, const FirstVertex& v) {
  // Albedos lie in [0, 1] and normals' components in [-1, 1]: far inside the sums' range.
  if (layers.has(Aov::Albedo)) albedo[pixel] += to_fixed(v.albedo);
  if (layers.has(Aov::Normal)) normal[pixel] += to_fixed(Rgb({v.normal.x, v.normal.y, v.normal.z}));
  if (layers.has(Aov::Depth) && v.depth < std::ldexp(kExactSumMaxValue, depth_exponent)) {
    depth[pixel] += to_fixed(v.depth, depth_exponent);
    ++depth_samples[pixel];
  }
}

void AovSums::add(size_t pixel, const AovSums& from, size_t from_pixel) {
  if (layers.has(Aov::Albedo)) albedo[pixel] += from.albedo[from_pixel];
  if (layers.has(Aov::Normal)) normal[pixel] += from.normal[from_pixel];
  if (layers.has(Aov::Depth)) {
    depth[pixel] += from.depth[from_pixel];
    depth_samples[pixel] += from.depth_samples[from_pixel];
  }
  if (layers.has(Aov::Half)) half[pixel] += from.half[from_pixel];
}

void AovSums::clear(size_t pixel) {
  for_each_vector([&](auto& v) { v[pixel] = {}; });
}

Rgb AovSums::albedo_mean(size_t pixel, uint32_t samples) const {
  return samples > 0 ? albedo[pixel].value() / double(samples) : Rgb(0.0);
}

Vec3 AovSums::normal_mean(size_t pixel, uint32_t samples) const {
  if (samples == 0) return {};
  const Rgb n = normal[pixel].value() / double(samples);
  return {n[0], n[1], n[2]};
}

double AovSums::depth_mean(size_t pixel) const {
  const uint32_t n = depth_samples[pixel];
  return n > 0 ? from_fixed(depth[pixel], depth_exponent) / double(n) : kInf;
}

size_t aov_film_bytes(AovSet aovs) {
  size_t bytes = 0;
  AovSums(aovs, 0, 0).for_each_vector([&](const auto& v) {
    bytes += sizeof(typename std::decay_t<decltype(v)>::value_type);
  });
  return bytes;
}

int aov_image_floats(AovSet aovs) {
  int floats = 0;
  for (Aov a : kAllAovs)
    if (aovs.has(a)) floats += a == Aov::Depth || a == Aov::Samples ? 1 : 3;
  return floats;
}

}  // namespace nimbus
