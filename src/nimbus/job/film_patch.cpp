#include "nimbus/job/film_patch.h"

#include <cstring>
#include <stdexcept>
#include <type_traits>

namespace nimbus {

static_assert(std::is_trivially_copyable_v<ExactRgb> && std::is_trivially_copyable_v<Rgb> &&
              std::is_trivially_copyable_v<int128>);

FilmPatch copy_patch(const Film& film, const PixelRect& r) {
  FilmPatch p;
  p.rect = r;
  p.samples.reserve(r.pixels());
  p.sum.reserve(r.pixels());
  p.sum_sq.reserve(r.pixels());
  p.aov = AovSums(film.aov.layers, size_t(r.pixels()), film.aov.depth_exponent);
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) {
      const size_t i = size_t(y) * film.width + x;
      p.aov.add(p.samples.size(), film.aov, i);
      p.samples.push_back(film.samples[i]);
      p.sum.push_back(film.sum[i]);
      p.sum_sq.push_back(film.sum_sq[i]);
    }
  return p;
}

FilmPatch take_patch(Film& film, const PixelRect& r) {
  FilmPatch p = copy_patch(film, r);
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) {
      const size_t i = size_t(y) * film.width + x;
      film.samples[i] = 0;
      film.sum[i] = ExactRgb{};
      film.sum_sq[i] = Rgb(0.0);
      film.aov.clear(i);
    }
  return p;
}

void merge_patch(Film& film, const FilmPatch& p) {
  const PixelRect& r = p.rect;
  if (r.x0 < 0 || r.y0 < 0 || r.x1 > film.width || r.y1 > film.height || r.x0 > r.x1 ||
      r.y0 > r.y1 || p.samples.size() != size_t(r.pixels()))
    throw std::invalid_argument("a film patch outside the film");
  if (p.aov.layers != film.aov.layers || p.aov.depth_exponent != film.aov.depth_exponent)
    throw std::invalid_argument("a film patch of other AOV layers than the film's");
  size_t k = 0;
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x, ++k) {
      const size_t i = size_t(y) * film.width + x;
      film.samples[i] += p.samples[k];
      film.sum[i] += p.sum[k];
      film.sum_sq[i] += p.sum_sq[k];
      film.aov.add(i, p.aov, k);
    }
}

namespace {

template <class T>
void append(std::vector<std::byte>& out, const T* data, size_t count) {
  const size_t at = out.size();
  out.resize(at + sizeof(T) * count);
  if (count > 0) std::memcpy(out.data() + at, data, sizeof(T) * count);
}

template <class T>
void extract(std::span<const std::byte>& in, T* data, size_t count) {
  if (in.size() < sizeof(T) * count) throw std::runtime_error("a film patch cut short");
  if (count > 0) std::memcpy(data, in.data(), sizeof(T) * count);
  in = in.subspan(sizeof(T) * count);
}

}  // namespace

std::vector<std::byte> pack_patch(const FilmPatch& p) {
  std::vector<std::byte> out;
  append(out, &p.rect, 1);
  append(out, p.samples.data(), p.samples.size());
  append(out, p.sum.data(), p.sum.size());
  append(out, p.sum_sq.data(), p.sum_sq.size());
  const uint8_t layers = p.aov.layers.bits();
  append(out, &layers, 1);
  append(out, &p.aov.depth_exponent, 1);
  p.aov.for_each_vector([&](const auto& v) { append(out, v.data(), v.size()); });
  return out;
}

FilmPatch unpack_patch(std::span<const std::byte> in) {
  FilmPatch p;
  extract(in, &p.rect, 1);
  const PixelRect& r = p.rect;
  if (r.x0 < 0 || r.y0 < 0 || r.x0 > r.x1 || r.y0 > r.y1 || r.x1 > 1 << 16 || r.y1 > 1 << 16)
    throw std::runtime_error("a film patch with a bad rectangle");
  const size_t n = size_t(r.pixels());
  p.samples.resize(n);
  p.sum.resize(n);
  p.sum_sq.resize(n);
  extract(in, p.samples.data(), n);
  extract(in, p.sum.data(), n);
  extract(in, p.sum_sq.data(), n);
  uint8_t layers = 0;
  int depth_exponent = 0;
  extract(in, &layers, 1);
  extract(in, &depth_exponent, 1);
  if (layers != AovSet::from_bits(layers).recorded().bits())
    throw std::runtime_error("a film patch with unknown AOV layers");
  p.aov = AovSums(AovSet::from_bits(layers), n, depth_exponent);
  p.aov.for_each_vector([&](auto& v) { extract(in, v.data(), v.size()); });
  if (!in.empty()) throw std::runtime_error("trailing bytes after a film patch");
  return p;
}

}  // namespace nimbus
