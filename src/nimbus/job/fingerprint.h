#pragma once
// What a checkpoint must match to be continued (job/checkpoint.h): everything that changes a
// pixel's samples. The scene's document as loaded, after the --set overrides (--seed included),
// its render settings (film, integrator, spectrum) each spelt out with its value, given or the
// default, without integrator.spp, which only says how many samples to take; the record of every
// file compiling it read (compile_scene's `inputs`: VDB grids, wherever the document names them,
// with their sizes and hashes taken as they were read); the nimbus version. Not the threads, the
// processes or the outputs, which change no pixel. Nothing is read or parsed again.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "nimbus/render/scene.h"
#include "nimbus/scene/scene_desc.h"

namespace nimbus {

// The fingerprint of a loaded description whose compilation read `inputs`. A scene built in code
// has no document: pass `identity`, any JSON that changes when the scene does, to stand for it.
nlohmann::json render_fingerprint(const SceneDesc& desc, const std::vector<InputFile>& inputs);
nlohmann::json render_fingerprint(const nlohmann::json& identity);

// "" when equal; else the first difference in words: "KEY: A in the checkpoint, B now" with KEY
// a dotted path (scene.integrator.seed), or which file read by the scene is not the one the
// checkpoint's render read.
std::string fingerprint_difference(const nlohmann::json& saved, const nlohmann::json& now);

// A hash of every majorant octree of the scene (nodes and bounds, to the bit): processes that
// compiled the same scene must agree on it.
uint64_t majorant_hash(const Scene& scene);

}  // namespace nimbus
