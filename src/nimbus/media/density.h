#pragma once
// A medium's density: the factor on its coefficients sigma_a, sigma_s at a point (docs/design.md,
// "Plug-in types"). A density answers two questions, its value at a point and a conservative
// range over a box; the lookups (medium_field.h) and the majorant octree (octree.h) ask nothing
// else, so a constant, an object's own function, a procedural cloud and a voxel grid are equals.
// Each type is one file pair in media/ and one entry in scene/density_types.cpp, which reads
// its parameters (docs/architecture.md, "Add a density").

#include <memory>

#include "nimbus/math/box.h"
#include "nimbus/math/interval.h"
#include "nimbus/math/vec3.h"

namespace nimbus {

class Density {
 public:
  virtual ~Density() = default;
  // Whether value() reads F, the holding object's function at the point; if not, callers need
  // not evaluate it.
  virtual bool uses_F() const = 0;
  // The density (>= 0) at the world point x, where the holding object's function is F (> 0
  // inside the object).
  virtual double value(const Vec3& x, double F) const = 0;
  // [lo, hi] bounding value() over the box, given that F lies in F_range there.
  virtual Interval range(const Box& box, const Interval& F_range) const = 0;
};

using DensityPtr = std::shared_ptr<const Density>;

}  // namespace nimbus
