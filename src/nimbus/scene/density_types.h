#pragma once
// The density types a scene file can name (media/density.h): one table from the name of
// "density": {"type": ...} to the reader of that type's own keys, which says how to make it.
// Adding a type is one file pair in media/ and one entry here (docs/architecture.md).

#include <string_view>
#include <vector>

#include "nimbus/media/density.h"
#include "nimbus/scene/input_file.h"
#include "nimbus/scene/json_reader.h"

namespace nimbus {

// How a density is made once the scene is compiled (a "vdb" density reads its file then).
using DensityMaker = Deferred<DensityPtr>;

struct DensityType {
  std::string_view name;
  // Reads and checks the type's keys from the density's object (the loader reads "type" and
  // "scale", and rejects any key no one read), and returns how to make the density.
  DensityMaker (*read)(JsonObject& params);
};

const std::vector<DensityType>& density_types();

// The names of density_types(), in order, for messages.
std::vector<std::string_view> density_type_names();

}  // namespace nimbus
