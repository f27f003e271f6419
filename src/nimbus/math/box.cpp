#include "nimbus/math/box.h"

#include <cmath>
#include <utility>

namespace nimbus {

bool Box::finite() const {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(lo[i]) || !std::isfinite(hi[i])) return false;
  return !empty();
}

bool clip_ray(const Box& box, const Ray& ray, double& t0, double& t1) {
  if (box.empty()) return false;
  for (int i = 0; i < 3; ++i) {
    const double inv = 1.0 / ray.d[i];
    double ta = (box.lo[i] - ray.o[i]) * inv;
    double tb = (box.hi[i] - ray.o[i]) * inv;
    if (ta > tb) std::swap(ta, tb);
    // NaN arises for a zero direction component with the origin on a face: keep the interval.
    if (ta > t0) t0 = ta;
    if (tb < t1) t1 = tb;
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace nimbus
