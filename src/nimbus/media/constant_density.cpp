#include "nimbus/media/constant_density.h"

namespace nimbus {

DensityPtr make_constant_density() {
  return std::make_shared<ConstantDensity>();
}

}  // namespace nimbus
