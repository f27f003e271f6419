#pragma once
// Ray–surface intersection of compiled shapes, exact to double precision: analytic for a single
// quadric, piecewise-polynomial root isolation for a flat free form (eq. 1–2), the leaves' roots
// for CSG of quadrics, conservative interval subdivision along the ray for everything else.
// Never marches with a fixed step.

#include <optional>

#include "nimbus/frep/tape.h"
#include "nimbus/math/ray.h"

namespace nimbus {

// The first t in [t_min, t_max] where F(o + t d) changes sign, i.e. where the ray enters or
// leaves {F > 0}; the ray may start inside or outside. d need not be unit length. Searches
// within tape.search_box. Thread-safe; allocates only when a thread first meets a tape with
// more quadrics than any before (per-thread scratch for the CSG and general paths).
std::optional<double> first_hit(const Tape& tape, const Ray& ray, double t_min, double t_max);

}  // namespace nimbus
