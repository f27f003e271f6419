#pragma once
// The density 1 everywhere in the holding object (the medium's scale sets its value).

#include "nimbus/media/density.h"

namespace nimbus {

class ConstantDensity final : public Density {
 public:
  bool uses_F() const override { return false; }
  double value(const Vec3&, double) const override { return 1.0; }
  Interval range(const Box&, const Interval&) const override { return {1.0, 1.0}; }
};

DensityPtr make_constant_density();

}  // namespace nimbus
