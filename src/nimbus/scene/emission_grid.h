#pragma once
// A medium's "emission" given as a temperature grid (docs/scene-format.md, media):
// {"file": "fire.vdb", "grid": "temperature", "scale": 1, "transform": [...]}, read into the
// medium's blackbody emission (media/temperature_emission.h). The loader hands an emission
// object here when it has a "file" or "grid" key; any other emission is a colour.

#include <memory>

#include "nimbus/media/temperature_emission.h"
#include "nimbus/scene/input_file.h"
#include "nimbus/scene/json_reader.h"

namespace nimbus {

// Whether an "emission" value is a temperature grid rather than a colour.
bool is_emission_grid(const JsonValue& v);

// How a temperature grid is made once the scene is compiled, which reads its file.
using EmissionGridMaker = Deferred<std::shared_ptr<const TemperatureEmission>>;

// Reads and checks the keys; the grid is read by the maker, and every problem, the file's
// included, is one SceneError line at the key at fault (the emission's own pointer for a
// problem of the default grid).
EmissionGridMaker read_emission_grid(const JsonValue& v);

}  // namespace nimbus
