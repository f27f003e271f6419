#pragma once
// Conservative axis-aligned bounds of the inside {F > 0} of a compiled shape.

#include "nimbus/math/box.h"

namespace nimbus {

struct Tape;
struct Quadric;

// The box of {q > 0} for one quadric (an ellipsoid, elliptic cylinder or slab), padded against
// the formula's round-off; everything when that set is unbounded, empty when it is empty.
Box quadric_box(const Quadric& q);

struct Bounds {
  Box box;               // contains every point with F > 0; empty for an empty shape
  bool bounded = false;  // false when some axis is infinite (half-spaces, infinite cylinders…)
};

// Analytic boxes of the quadric leaves, combined along the tape (union: hull, intersection:
// intersection, difference: the first operand, free form: hull of the base and the positive
// perturbations), then tightened by interval subdivision when finite.
Bounds compute_bounds(const Tape& tape);

}  // namespace nimbus
