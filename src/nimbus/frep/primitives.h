#pragma once
// Named primitives, all compiled to quadrics of eq. 3 (the box to three slabs).
// Parameterisations (F > 0 inside); preconditions are checked by the scene loader:
//   sphere      F = r² − |x − c|²                                  r > 0
//   ellipsoid   F = 1 − Σ_i ((x_i − c_i) / r_i)²                   r_i > 0
//   cylinder    F = r² − |(x − p) − ((x − p)·a)a|²   (infinite)    r > 0, a ≠ 0 (normalised)
//   cone        F = ((x − v)·a)² − |x − v|² cos²θ  (both nappes, apex v, half-angle θ)
//                                                                  0 < θ < 90°
//   paraboloid  F = 4 f (x − v)·a − |(x − v) − ((x − v)·a)a|²  (opens along +a)   f > 0
//   halfspace   F = −(x − p)·n       (n points out of the solid)   n ≠ 0
//   slab        F = (w/2)² − ((x − c)·n)²   (thickness w, centred on c)          w > 0
//   box         min of three axis slabs between lo and hi                        lo < hi

#include "nimbus/frep/quadric.h"
#include "nimbus/frep/shape_desc.h"
#include "nimbus/math/vec3.h"

namespace nimbus {

Quadric sphere(const Vec3& center, double radius);
Quadric ellipsoid(const Vec3& center, const Vec3& radii);
Quadric cylinder(const Vec3& point, const Vec3& axis, double radius);
Quadric cone(const Vec3& apex, const Vec3& axis, double half_angle_degrees);
Quadric paraboloid(const Vec3& vertex, const Vec3& axis, double focal_length);
Quadric halfspace(const Vec3& point, const Vec3& normal);
Quadric slab(const Vec3& center, const Vec3& normal, double thickness);
ShapePtr box(const Vec3& lo, const Vec3& hi);

}  // namespace nimbus
