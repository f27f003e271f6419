#include "nimbus/media/field_density.h"

namespace nimbus {

DensityPtr make_field_density() {
  return std::make_shared<FieldDensity>();
}

}  // namespace nimbus
