#include "nimbus/job/film_patch.h"

#include <cstring>
#include <stdexcept>
#include <type_traits>

namespace nimbus {

static_assert(std::is_trivially_copyable_v<ExactRgb> && std::is_trivially_copyable_v<Rgb>);

FilmPatch take_patch(Film& film, const PixelRect& r) {
  FilmPatch p;
  p.rect = r;
  p.samples.reserve(r.pixels());
  p.sum.reserve(r.pixels());
  p.sum_sq.reserve(r.pixels());
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) {
      const size_t i = size_t(y) * film.width + x;
      p.samples.push_back(film.samples[i]);
      p.sum.push_back(film.sum[i]);
      p.sum_sq.push_back(film.sum_sq[i]);
      film.samples[i] = 0;
      film.sum[i] = ExactRgb{};
      film.sum_sq[i] = Rgb(0.0);
    }
  return p;
}

void merge_patch(Film& film, const FilmPatch& p) {
  const PixelRect& r = p.rect;
  if (r.x0 < 0 || r.y0 < 0 || r.x1 > film.width || r.y1 > film.height || r.x0 > r.x1 ||
      r.y0 > r.y1 || p.samples.size() != size_t(r.pixels()))
    throw std::invalid_argument("a film patch outside the film");
  size_t k = 0;
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x, ++k) {
      const size_t i = size_t(y) * film.width + x;
      film.samples[i] += p.samples[k];
      film.sum[i] += p.sum[k];
      film.sum_sq[i] += p.sum_sq[k];
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
  if (!in.empty()) throw std::runtime_error("trailing bytes after a film patch");
  return p;
}

}  // namespace nimbus
