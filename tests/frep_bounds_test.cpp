#include <gtest/gtest.h>

#include <cmath>

#include "frep_gallery.h"
#include "nimbus/frep/bounds.h"
#include "nimbus/frep/tape.h"

namespace nimbus {
namespace frep_bounds_test {

using test::leaf;

TEST(Bounds, EllipsoidsAreExact) {
  const Tape s = compile(*leaf(sphere({0.5, -1, 2}, 1.5)));
  ASSERT_TRUE(s.bounds.bounded);
  const Vec3 center{0.5, -1, 2};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(s.bounds.box.lo[i], center[i] - 1.5, 1e-9);
    EXPECT_NEAR(s.bounds.box.hi[i], center[i] + 1.5, 1e-9);
  }
  // A rotated, translated ellipsoid: half-width along axis i is sqrt(Σ_j (R_ij r_j)²).
  const Vec3 radii{1.2, 0.3, 0.7}, centre{1, 2, 3};
  const Mat4 m = Mat4::translate(centre) * Mat4::rotate({1, 2, 3}, 50);
  const Tape e = compile(*leaf(ellipsoid({0, 0, 0}, radii), m));
  ASSERT_TRUE(e.bounds.bounded);
  for (int i = 0; i < 3; ++i) {
    double half = 0;
    for (int j = 0; j < 3; ++j) half += std::pow(m(i, j) * radii[j], 2);
    half = std::sqrt(half);
    EXPECT_NEAR(e.bounds.box.lo[i], centre[i] - half, 1e-9);
    EXPECT_NEAR(e.bounds.box.hi[i], centre[i] + half, 1e-9);
  }
}

TEST(Bounds, DegenerateQuadricsAreBoundedAcrossTheirAxis) {
  // A z-cylinder rotated onto the y axis (round-off in the rotation must not unbound x or z).
  const Tape c = compile(*leaf(cylinder({1, 0, 2}, {0, 0, 1}, 0.5),
                               Mat4::translate({0, 0, 0}) * Mat4::rotate({1, 0, 0}, 90)));
  EXPECT_FALSE(c.bounds.bounded);
  EXPECT_NEAR(c.bounds.box.lo.x, 0.5, 1e-9);
  EXPECT_NEAR(c.bounds.box.hi.x, 1.5, 1e-9);
  EXPECT_NEAR(c.bounds.box.lo.z, -0.5, 1e-9);
  EXPECT_NEAR(c.bounds.box.hi.z, 0.5, 1e-9);
  EXPECT_TRUE(std::isinf(c.bounds.box.lo.y) && std::isinf(c.bounds.box.hi.y));
  const Tape s = compile(*leaf(slab({0, 0, 1}, {0, 0, 1}, 0.4)));
  EXPECT_FALSE(s.bounds.bounded);
  EXPECT_NEAR(s.bounds.box.lo.z, 0.8, 1e-9);
  EXPECT_NEAR(s.bounds.box.hi.z, 1.2, 1e-9);
  // A tilted cylinder cut by a slab along the same axis is bounded.
  const Vec3 axis = normalize(Vec3{1, 1, 1});
  const Tape capped = compile(
      *make_shape(CsgNode{CsgOp::Intersection,
                          {leaf(cylinder({0, 0, 0}, axis, 0.3)), leaf(slab({0, 0, 0}, axis, 2))}}));
  EXPECT_TRUE(capped.bounds.bounded);
}

TEST(Bounds, UnboundedShapesSaySo) {
  for (const Quadric& q :
       {halfspace({0, 0, 0}, {1, 2, 3}), cone({0, 0, 0}, {0, 0, 1}, 30),
        paraboloid({0, 0, 0}, {0, 1, 0}, 0.5), cylinder({0, 0, 0}, {1, 1, 0}, 1.0)})
    EXPECT_FALSE(compile(*leaf(q)).bounds.bounded);
  // A hyperboloid of one sheet, x² + y² − z² < 1 (F = 1 − x² − y² + z²).
  EXPECT_FALSE(compile(*leaf(Quadric{{-1, -1, 1, 0, 0, 0, 0, 0, 0, 1}})).bounds.bounded);
  // Union with an unbounded shape is unbounded; a difference keeps the first operand's box.
  EXPECT_FALSE(compile(*make_shape(CsgNode{
                           CsgOp::Union,
                           {leaf(sphere({0, 0, 0}, 1)), leaf(halfspace({0, 0, 0}, {0, 0, 1}))}}))
                   .bounds.bounded);
  EXPECT_TRUE(compile(*make_shape(CsgNode{
                          CsgOp::Difference,
                          {leaf(sphere({0, 0, 0}, 1)), leaf(halfspace({0, 0, 0}, {0, 0, 1}))}}))
                  .bounds.bounded);
}

// Every gallery shape: the box holds all of 10⁵ inside points found by rejection sampling, and
// exceeds their extent by at most 3 % of it on each face.
TEST(Bounds, GalleryBoxesAreConservativeAndTight) {
  Rng rng(8);
  for (const auto& g : test::gallery()) {
    const Tape tape = compile(*g.shape);
    ASSERT_TRUE(tape.bounds.bounded) << g.name;
    const Box& box = tape.bounds.box;
    Box seen;
    for (int found = 0; found < 100000;) {
      const Vec3 x = g.centre + test::random_in_cube(rng, g.radius);
      if (!(evaluate(tape, x) > 0)) continue;
      ++found;
      ASSERT_TRUE(box.contains(x)) << g.name;
      seen = unite(seen, Box{x, x});
    }
    const Vec3 extent = seen.extent();
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(seen.lo[i] - box.lo[i], 0.03 * extent[i]) << g.name << " axis " << i;
      EXPECT_LE(box.hi[i] - seen.hi[i], 0.03 * extent[i]) << g.name << " axis " << i;
    }
  }
}

}  // namespace frep_bounds_test
}  // namespace nimbus
