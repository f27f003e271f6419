#pragma once
// A render job's state in a file, to continue it later (`nimbus render --checkpoint`,
// `--resume`): the film (sums, sums of squares and per-pixel sample counts, io/film_file.h),
// the samples per pixel the job was asked for, the fingerprint of what it rendered
// (job/fingerprint.h) and the hash of its majorant octrees.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "nimbus/render/film.h"

namespace nimbus {

struct Checkpoint {
  nlohmann::json fingerprint;
  uint64_t majorants = 0;  // majorant_hash of the scene
  int spp = 0;             // the samples per pixel the job was to reach
  Film film;
};

// Writes atomically (io/atomic_file.h): a reader sees the previous checkpoint or this one.
void save_checkpoint(const Checkpoint& checkpoint, const std::string& path);

// std::runtime_error("PATH: problem") for a missing file, another kind of file, another version,
// or one cut short.
Checkpoint load_checkpoint(const std::string& path);

// Pixel samples the film holds, summed over its pixels.
uint64_t samples_held(const Film& film);

}  // namespace nimbus
