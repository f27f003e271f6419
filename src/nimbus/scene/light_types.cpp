#include "nimbus/scene/light_types.h"

#include "nimbus/scene/colour_reader.h"
#include "nimbus/scene/load.h"

namespace nimbus {
namespace {

// docs/scene-format.md, "lights": the keys of each type. Emission is radiance for lights seen
// over a solid angle, irradiance for a directional light, intensity for a point light.
SpectralParam emission(JsonObject& o, const char* key) {
  return read_colour(o.required(key), SpectralRole::Illuminant, kEmission);
}

void read_environment(JsonObject& o, Light& l) {
  l.type = Light::Type::Environment;
  l.emission = emission(o, "radiance");
}

void read_directional(JsonObject& o, Light& l) {
  l.type = Light::Type::Directional;
  // Normalised twice, as the loader and then the compiler did when they were two steps: the
  // second rounds differently in the last bit, and images keep their bits (image checksums).
  l.direction = normalize(normalize(o.required("direction").direction()));
  l.emission = emission(o, "irradiance");
}

void read_point(JsonObject& o, Light& l) {
  l.type = Light::Type::Point;
  l.position = o.required("position").vec3(kCoordinate);
  l.emission = emission(o, "intensity");
}

void read_sphere(JsonObject& o, Light& l) {
  l.type = Light::Type::Sphere;
  l.center = o.required("center").vec3(kCoordinate);
  l.radius = o.required("radius").number(kLength);
  l.emission = emission(o, "radiance");
}

}  // namespace

const std::vector<LightType>& light_types() {
  static const std::vector<LightType> types = {
      {"environment", read_environment},
      {"directional", read_directional},
      {"point", read_point},
      {"sphere", read_sphere},
  };
  return types;
}

}  // namespace nimbus
