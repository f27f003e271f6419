#include "nimbus/media/temperature_emission.h"

#include <utility>

namespace nimbus {

std::shared_ptr<const TemperatureEmission> make_temperature_emission(VdbParams params,
                                                                     double scale) {
  params.quantity = "temperature";
  auto e = std::make_shared<TemperatureEmission>();
  e->kelvin = make_vdb_density(params);
  e->scale = scale;
  planck_rgb(1000);
  return e;
}

}  // namespace nimbus
