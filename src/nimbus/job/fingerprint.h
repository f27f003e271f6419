#pragma once
// What a checkpoint must match to be continued (job/checkpoint.h): everything that changes a
// pixel's samples. The scene document after the --set overrides (--seed included), without
// integrator.spp, which only says how many samples to take; the content of every file the loader
// read for it (SceneDesc::inputs: VDB grids, wherever the document names them); the nimbus
// version. Not the threads, the processes or the outputs, which change no pixel.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "nimbus/render/scene.h"
#include "nimbus/scene/input_file.h"

namespace nimbus {

// FNV-1a, 64 bits: a checksum, not a cryptographic hash.
uint64_t hash_bytes(std::span<const std::byte> bytes, uint64_t h = 0xcbf29ce484222325ull);

// The fingerprint of a scene file loaded with these overrides, `inputs` being the files that
// loading read (SceneDesc::inputs); call it once load_scene_file has accepted them (its errors
// are a loader's: SceneError).
nlohmann::json render_fingerprint(const std::string& scene_path,
                                  const std::vector<std::string>& overrides,
                                  const std::vector<InputFile>& inputs);

// "" when equal; else the first difference, as "KEY: A in the checkpoint, B now" with KEY a
// dotted path (integrator.seed, files./media/m/density/file).
std::string fingerprint_difference(const nlohmann::json& saved, const nlohmann::json& now);

// A hash of every majorant octree of the scene (nodes and bounds, to the bit): processes that
// compiled the same scene must agree on it.
uint64_t majorant_hash(const Scene& scene);

}  // namespace nimbus
