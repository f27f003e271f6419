#include "nimbus/media/medium_field.h"

#include <algorithm>

namespace nimbus {

double medium_density(const Medium& medium, const Vec3& x, double F) {
  switch (medium.density) {
    case Medium::Density::Constant:
      return medium.scale;
    case Medium::Density::Field:
      return medium.scale * std::max(F, 0.0);
    case Medium::Density::Cloud:
      return medium.scale * cloud_density(medium.cloud, x, F);
  }
  return 0.0;
}

}  // namespace nimbus
