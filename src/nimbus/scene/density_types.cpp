#include "nimbus/scene/density_types.h"

#include "nimbus/media/cloud_density.h"
#include "nimbus/media/constant_density.h"
#include "nimbus/media/field_density.h"

namespace nimbus {
namespace {

DensityPtr read_constant(JsonObject&) {
  return make_constant_density();
}

DensityPtr read_field(JsonObject&) {
  return make_field_density();
}

// docs/scene-format.md: noise octaves and base frequency, erosion depth in [0, 1), the F over
// which the profile rises from 0 to 1, and the noise seed (0 in scene files).
DensityPtr read_cloud(JsonObject& d) {
  CloudParams p;
  p.seed = 0;
  if (auto y = d.optional("octaves")) p.octaves = y->integer(between(1, 16));
  if (auto y = d.optional("frequency")) p.frequency = y->number(above(0));
  if (auto y = d.optional("amplitude")) p.amplitude = y->number(Range{0.0, 1.0, false, true});
  if (auto y = d.optional("edge")) p.edge = y->number(above(0));
  if (auto y = d.optional("seed")) p.seed = y->unsigned_integer();
  return make_cloud_density(p);
}

}  // namespace

const std::vector<DensityType>& density_types() {
  static const std::vector<DensityType> types = {
      {"constant", read_constant},
      {"field", read_field},
      {"cloud", read_cloud},
  };
  return types;
}

std::vector<std::string_view> density_type_names() {
  std::vector<std::string_view> names;
  for (const DensityType& t : density_types()) names.push_back(t.name);
  return names;
}

}  // namespace nimbus
