#include "nimbus/media/medium_field.h"

namespace nimbus {

double medium_density(const Medium& medium, const Vec3& x, double F) {
  return medium.scale * medium.density->value(x, F);
}

}  // namespace nimbus
