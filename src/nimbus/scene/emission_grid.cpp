#include "nimbus/scene/emission_grid.h"

#include <filesystem>

#include "nimbus/scene/load.h"

namespace nimbus {

bool is_emission_grid(const JsonValue& v) {
  return v.json().is_object() && (v.json().contains("file") || v.json().contains("grid"));
}

std::shared_ptr<const TemperatureEmission> read_emission_grid(const JsonValue& v) {
  JsonObject o(v);
  const JsonValue file = o.required("file");
  const auto grid = o.optional("grid");
  const auto scale = o.optional("scale");
  const auto transform = o.optional("transform");
  VdbParams p;
  p.grid = "temperature";
  const std::filesystem::path path = file.string();
  if (path.empty()) file.fail("must name a file");
  // Relative to the scene file's folder, as the "vdb" density's file.
  p.file = (std::filesystem::path(v.origin().folder) / path).string();
  if (grid) p.grid = grid->string();
  if (p.grid.empty()) grid->fail("must name a grid");
  const double s = scale ? scale->number(at_least(0)) : 1.0;
  if (transform) p.transform = read_transform(*transform);
  // A misspelt key is reported before the file is read with a default in its place.
  o.finish("for a temperature grid's emission");
  file.record_input(p.file);
  try {
    return make_temperature_emission(p, s);
  } catch (const VdbError& e) {
    if (e.key != "grid") file.fail(e.what());
    if (grid) grid->fail(e.what());
    o.fail(e.what());
  }
}

}  // namespace nimbus
