#pragma once
// The --stats report of a render, as JSON.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "nimbus/render/renderer.h"

namespace nimbus {

// `samples`: the pixel samples this run rendered, which samples_per_second and the per-sample
// counters divide by: the run's counters and time are its own, also where it resumed a
// checkpoint's film or was stopped before the image's width × height × spp.
nlohmann::json render_stats(const Scene& scene, const RenderResult& result,
                            const std::string& scene_path, std::uint64_t samples);

}  // namespace nimbus
