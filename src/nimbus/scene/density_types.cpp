#include "nimbus/scene/density_types.h"

#include "nimbus/media/cloud_density.h"
#include "nimbus/media/constant_density.h"
#include "nimbus/media/field_density.h"
#include "nimbus/media/pattern_density.h"
#include "nimbus/media/vdb_density.h"
#include "nimbus/scene/load.h"

namespace nimbus {
namespace {

DensityMaker read_constant(JsonObject&) {
  return [](std::vector<InputFile>&) { return make_constant_density(); };
}

DensityMaker read_field(JsonObject&) {
  return [](std::vector<InputFile>&) { return make_field_density(); };
}

// docs/scene-format.md: noise octaves and base frequency, erosion depth in [0, 1), the F over
// which the profile rises from 0 to 1, and the noise seed (0 in scene files).
DensityMaker read_cloud(JsonObject& d) {
  CloudParams p;
  p.seed = 0;
  if (auto y = d.optional("octaves")) p.octaves = y->integer(between(1, 16));
  if (auto y = d.optional("frequency")) p.frequency = y->number(kLength);
  if (auto y = d.optional("amplitude")) p.amplitude = y->number(Range{0.0, 1.0, false, true});
  if (auto y = d.optional("edge")) p.edge = y->number(above(0));
  if (auto y = d.optional("seed")) p.seed = y->unsigned_integer();
  return [p](std::vector<InputFile>&) { return make_cloud_density(p); };
}

// docs/scene-format.md, "Textures": the solid patterns' frequency, octaves and seed; veins also
// their direction, turbulence, noise frequency and sharpness.
DensityMaker read_pattern(JsonObject& d, PatternParams::Kind kind) {
  PatternParams p;
  p.kind = kind;
  if (auto y = d.optional("frequency")) p.frequency = y->number(kLength);
  if (auto y = d.optional("octaves")) p.octaves = y->integer(between(1, 16));
  if (auto y = d.optional("seed")) p.seed = y->unsigned_integer();
  if (kind == PatternParams::Kind::Veins) {
    if (auto y = d.optional("direction")) p.direction = normalize(normalize(y->direction()));
    if (auto y = d.optional("turbulence")) p.turbulence = y->number(between(0, 1e3));
    if (auto y = d.optional("noise_frequency")) p.noise_frequency = y->number(kLength);
    if (auto y = d.optional("sharpness")) p.sharpness = y->number(between(1, 1e3));
  }
  return [p](std::vector<InputFile>&) { return make_pattern_density(p); };
}

DensityMaker read_noise(JsonObject& d) {
  return read_pattern(d, PatternParams::Kind::Noise);
}

DensityMaker read_turbulence(JsonObject& d) {
  return read_pattern(d, PatternParams::Kind::Turbulence);
}

DensityMaker read_veins(JsonObject& d) {
  return read_pattern(d, PatternParams::Kind::Veins);
}

// docs/scene-format.md: a grid of a .vdb or .nvdb file (relative to the scene file's folder), by
// name, moved further by an optional transform. The file is read when the scene is compiled;
// every problem with it is then one line naming the key at fault and the file.
DensityMaker read_vdb(JsonObject& d) {
  const JsonValue file = d.required("file");
  const auto grid = d.optional("grid");
  const auto transform = d.optional("transform");
  GridInput in;
  in.params.file = file.file();
  if (grid) in.params.grid = grid->string();
  if (in.params.grid.empty()) grid->fail("must name a grid");
  if (transform) in.params.transform = read_transform(*transform);
  d.finish(R"(for density type "vdb")");
  in.file_pointer = file.pointer();
  in.file_blame = file.blame();
  if (grid) in.grid_blame = grid->blame();
  in.object_blame = d.value().blame();
  return [in](std::vector<InputFile>& inputs) { return in.read(inputs, make_vdb_density); };
}

}  // namespace

const std::vector<DensityType>& density_types() {
  static const std::vector<DensityType> types = {
      {"constant", read_constant}, {"field", read_field}, {"cloud", read_cloud},
      {"vdb", read_vdb},           {"noise", read_noise}, {"turbulence", read_turbulence},
      {"veins", read_veins},
  };
  return types;
}

std::vector<std::string_view> density_type_names() {
  std::vector<std::string_view> names;
  for (const DensityType& t : density_types()) names.push_back(t.name);
  return names;
}

}  // namespace nimbus
