#pragma once
// A film (render/film.h) in a file, to resume or extend a render and to merge renders made
// elsewhere.

#include <cstdint>
#include <iosfwd>
#include <string>

#include "nimbus/render/film.h"

namespace nimbus {

// Saves the film to a file, atomically (io/atomic_file.h): a versioned little-endian binary of
// the size, the exponent, the AOV layers and their depth exponent, then per pixel the count, the
// three exact sums (128-bit fixed point, in units of 2^(exponent - 64)) and the three sums of
// squares (doubles), then each AOV sum held for every pixel (render/aov.h, AovSums).
void save_film(const Film& film, const std::string& path);

// Loads a film saved by save_film; std::runtime_error("PATH: problem") if the file is missing or
// not a regular file, not a film, of another version, damaged, cut short, followed by other
// bytes, or larger than the memory available.
Film load_film(const std::string& path);

// The same bytes on a stream, for files that hold a film among other things (job/checkpoint.h).
// read_film stops after the film; `name` prefixes its errors; `bytes` is what the stream holds
// from the film on, which the sizes in its header are checked against before any allocation.
void write_film(std::ostream& out, const Film& film);
Film read_film(std::istream& in, const std::string& name, uint64_t bytes);

}  // namespace nimbus
