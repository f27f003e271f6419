#pragma once
// Shapes shared by the FRep tests: every kind the tape compiles (quadrics, flat and nested free
// forms, CSG), with transforms, each inside a known ball so that tests can sample around it.

#include <cmath>
#include <string>
#include <vector>

#include "nimbus/frep/primitives.h"
#include "nimbus/frep/shape_desc.h"
#include "nimbus/math/mat4.h"
#include "nimbus/math/rng.h"

namespace nimbus::test {

struct GalleryShape {
  std::string name;
  ShapePtr shape;
  Vec3 centre;  // F <= 0 outside the ball (centre, radius), by construction
  double radius;
};

inline Vec3 random_in_cube(Rng& rng, double half) {
  return {half * (2 * rng.uniform() - 1), half * (2 * rng.uniform() - 1),
          half * (2 * rng.uniform() - 1)};
}

inline Vec3 random_unit(Rng& rng) {
  while (true) {
    const Vec3 v = random_in_cube(rng, 1);
    const double l = length(v);
    if (l > 1e-3 && l <= 1) return v / l;
  }
}

inline Mat4 random_rigid(Rng& rng, double max_shift) {
  return Mat4::translate(random_in_cube(rng, max_shift)) *
         Mat4::rotate(random_unit(rng), 360 * rng.uniform());
}

inline Mat4 random_affine(Rng& rng) {
  return random_rigid(rng, 2) *
         Mat4::scale({0.5 + rng.uniform(), 0.5 + rng.uniform(), 0.5 + rng.uniform()}) *
         Mat4::rotate(random_unit(rng), 360 * rng.uniform());
}

inline ShapePtr leaf(const Quadric& q, const Mat4& m = Mat4::identity()) {
  return make_shape(QuadricNode{q}, m);
}

// A unit sphere with `count` spherical bumps on its surface: weights of both signs scaled so
// that w r⁶ (the bump's peak) is O(1); every fourth one thin (radius 0.05–0.1) and tall.
inline ShapePtr bumpy_sphere(Rng& rng, int count) {
  FreeFormNode ff{leaf(sphere({0, 0, 0}, 1.0)), {}};
  for (int i = 0; i < count; ++i) {
    const bool thin = i % 4 == 3;
    const double r = thin ? 0.05 + 0.05 * rng.uniform() : 0.15 + 0.35 * rng.uniform();
    const double peak = thin ? 0.4 + 0.3 * rng.uniform() : 0.2 + 0.6 * rng.uniform();
    const double sign = !thin && i % 3 == 1 ? -1.0 : 1.0;
    ff.perturbations.push_back({leaf(sphere(random_unit(rng), r)), sign * peak / std::pow(r, 6)});
  }
  return make_shape(std::move(ff));
}

inline std::vector<GalleryShape> gallery() {
  Rng rng(2024);
  std::vector<GalleryShape> shapes;
  shapes.push_back({"sphere", leaf(sphere({0.1, -0.2, 0.3}, 1.0)), {0.1, -0.2, 0.3}, 1.01});
  shapes.push_back({"ellipsoid",
                    leaf(ellipsoid({0, 0, 0}, {1.2, 0.3, 0.7}), random_rigid(rng, 0)),
                    {0, 0, 0},
                    1.21});
  {
    const Vec3 axis = normalize(Vec3{1, 2, 0.5});
    CsgNode clipped{CsgOp::Intersection,
                    {leaf(cylinder({0, 0, 0}, axis, 0.6)), leaf(slab({0, 0, 0}, axis, 1.5))}};
    shapes.push_back({"clipped_cylinder", make_shape(std::move(clipped)), {0, 0, 0}, 1.0});
  }
  {
    FreeFormNode one{leaf(ellipsoid({0, 0, 0}, {1, 0.8, 0.6})),
                     {{leaf(sphere({0.8, 0.3, 0}, 0.45)), 0.8 / std::pow(0.45, 6)}}};
    shapes.push_back(
        {"free_form_1", make_shape(std::move(one), Mat4::rotate({0, 0, 1}, 30)), {0, 0, 0}, 1.6});
  }
  shapes.push_back({"free_form_8", bumpy_sphere(rng, 8), {0, 0, 0}, 1.9});
  shapes.push_back({"free_form_32", bumpy_sphere(rng, 32), {0, 0, 0}, 1.9});
  {
    // A free form whose perturbations are a (transformed) free form and a CSG, inside a rotated,
    // scaled outer free form.
    FreeFormNode inner{leaf(ellipsoid({0, 0, 0}, {0.5, 0.3, 0.3})),
                       {{leaf(sphere({0.4, 0, 0}, 0.2)), 0.5 / std::pow(0.2, 6)},
                        {leaf(sphere({0, 0.3, 0}, 0.15)), -0.5 / std::pow(0.15, 6)}}};
    const ShapePtr inner_shape =
        make_shape(std::move(inner), Mat4::translate({0.9, 0, 0}) * Mat4::rotate({0, 1, 1}, 40));
    CsgNode blob{CsgOp::Union,
                 {leaf(sphere({0, 0, 0.95}, 0.2)), leaf(sphere({0, 0.2, 0.95}, 0.15))}};
    FreeFormNode outer{leaf(sphere({0, 0, 0}, 1.0)),
                       {{inner_shape, 0.7}, {make_shape(std::move(blob)), 100.0}}};
    shapes.push_back(
        {"nested_free_form",
         make_shape(std::move(outer), Mat4::rotate({1, 0, 0}, 25) * Mat4::scale({1.1, 0.9, 1.0})),
         {0, 0, 0},
         2.2});
  }
  {
    CsgNode diff{CsgOp::Difference,
                 {leaf(sphere({0, 0, 0}, 1.0)), leaf(cylinder({0, 0, 0}, {0, 1, 1}, 0.35)),
                  leaf(sphere({0.9, 0, 0}, 0.4))}};
    shapes.push_back({"csg_difference", make_shape(std::move(diff)), {0, 0, 0}, 1.01});
  }
  {
    CsgNode uni{CsgOp::Union,
                {bumpy_sphere(rng, 4), leaf(ellipsoid({1.2, 0, 0}, {0.6, 0.2, 0.2}))}};
    shapes.push_back({"csg_union", make_shape(std::move(uni)), {0, 0, 0}, 2.0});
  }
  shapes.push_back(
      {"box",
       with_transform(box({-0.7, -0.4, -0.2}, {0.7, 0.4, 0.2}), Mat4::rotate({1, 1, 0}, 35)),
       {0, 0, 0},
       0.85});
  return shapes;
}

}  // namespace nimbus::test
