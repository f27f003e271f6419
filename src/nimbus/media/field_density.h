#pragma once
// The holding object's own function as the density, max(F, 0): zero on its surface, growing
// inward (for a quadric, 1 − |x|² in the unit sphere).

#include <algorithm>

#include "nimbus/media/density.h"

namespace nimbus {

class FieldDensity final : public Density {
 public:
  bool uses_F() const override { return true; }
  double value(const Vec3&, double F) const override { return std::max(F, 0.0); }
  Interval range(const Box&, const Interval& F) const override {
    return {std::max(F.lo, 0.0), std::max(F.hi, 0.0)};
  }
};

DensityPtr make_field_density();

}  // namespace nimbus
