#pragma once
// Conservative axis-aligned bounds of the inside {F > 0} of a compiled shape.

#include "nimbus/math/box.h"
#include "nimbus/math/mat4.h"

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

// Bounds of a shape placed by `placement` (tape: the placed shape), from `local`, the shape's
// own bounds (compute_bounds of it unplaced): the box around the placed corners of the local
// box, cut by the placed tape's analytic boxes. No search, so a shape placed many times is
// searched once; as tight as compute_bounds for translations and scales, looser (still
// enclosing) for rotations.
Bounds placed_bounds(const Tape& tape, const Bounds& local, const Mat4& placement);

}  // namespace nimbus
