#include "nimbus/math/box.h"

#include <cmath>
#include <utility>

namespace nimbus {

bool Box::finite() const {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(lo[i]) || !std::isfinite(hi[i])) return false;
  return !empty();
}

}  // namespace nimbus
