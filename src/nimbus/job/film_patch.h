#pragma once
// A rectangle of a film's pixels as plain data: what one work unit of a render job adds to the
// film (job/work_queue.h), moved between threads or processes and merged into the job's film.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "nimbus/render/film.h"

namespace nimbus {

struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // [x0, x1) x [y0, y1)
  int pixels() const { return (x1 - x0) * (y1 - y0); }
};

struct FilmPatch {
  PixelRect rect;
  std::vector<uint32_t> samples;  // row by row
  std::vector<ExactRgb> sum;
  std::vector<Rgb> sum_sq;
  AovSums aov;  // the film's AOV sums, for the rectangle's pixels
};

// The rectangle's pixels of `film`.
FilmPatch copy_patch(const Film& film, const PixelRect& rect);
// Moves the rectangle's pixels out of `film` (which then holds no samples there).
FilmPatch take_patch(Film& film, const PixelRect& rect);

// merge (render/film.h) of the patch into the film's rectangle: exact sums, counts added.
void merge_patch(Film& film, const FilmPatch& patch);

// The patch as bytes and back; unpack_patch throws std::runtime_error on bytes that are not a
// patch.
std::vector<std::byte> pack_patch(const FilmPatch& patch);
FilmPatch unpack_patch(std::span<const std::byte> bytes);

}  // namespace nimbus
