#include "nimbus/scene/emission_grid.h"

#include <filesystem>

#include "nimbus/scene/load.h"

namespace nimbus {

bool is_emission_grid(const JsonValue& v) {
  return v.json().is_object() && (v.json().contains("file") || v.json().contains("grid"));
}

EmissionGridMaker read_emission_grid(const JsonValue& v) {
  JsonObject o(v);
  const JsonValue file = o.required("file");
  const auto grid = o.optional("grid");
  const auto scale = o.optional("scale");
  const auto transform = o.optional("transform");
  GridInput in;
  in.params.grid = "temperature";
  const std::filesystem::path path = file.string();
  if (path.empty()) file.fail("must name a file");
  // Relative to the scene file's folder, as the "vdb" density's file.
  in.params.file = (std::filesystem::path(v.origin().folder) / path).string();
  if (grid) in.params.grid = grid->string();
  if (in.params.grid.empty()) grid->fail("must name a grid");
  const double s = scale ? scale->number(at_least(0)) : 1.0;
  if (transform) in.params.transform = read_transform(*transform);
  o.finish("for a temperature grid's emission");
  in.file_pointer = file.pointer();
  in.file_blame = file.blame();
  if (grid) in.grid_blame = grid->blame();
  in.object_blame = v.blame();
  return [in, s](std::vector<InputFile>& inputs) {
    return in.read(inputs, [s](const VdbParams& p) { return make_temperature_emission(p, s); });
  };
}

}  // namespace nimbus
