#pragma once
// The light types a scene file can name (render/light.h): one table from the name of
// "lights": [{"type": ...}] to the reader of that type's own keys.

#include <string_view>
#include <vector>

#include "nimbus/render/light.h"
#include "nimbus/scene/json_reader.h"

namespace nimbus {

struct LightType {
  std::string_view name;
  // Reads the type's keys from the light's object (the loader reads "type" and rejects any key
  // no one read) into `light`, whose type it sets.
  void (*read)(JsonObject& keys, Light& light);
};

const std::vector<LightType>& light_types();

}  // namespace nimbus
