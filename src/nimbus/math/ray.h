#pragma once
// A ray x(t) = o + t d. d need not be unit length for geometry queries.

#include "nimbus/math/vec3.h"

namespace nimbus {

struct Ray {
  Vec3 o;
  Vec3 d;
  constexpr Vec3 at(double t) const { return o + d * t; }
};

}  // namespace nimbus
