#pragma once
// The --stats report of a render, as JSON.

#include <nlohmann/json.hpp>
#include <string>

#include "nimbus/render/renderer.h"

namespace nimbus {

nlohmann::json render_stats(const Scene& scene, const RenderResult& result,
                            const std::string& scene_path);

}  // namespace nimbus
