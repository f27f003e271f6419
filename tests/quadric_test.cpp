#include "nimbus/frep/quadric.h"

#include <gtest/gtest.h>

#include "nimbus/frep/primitives.h"
#include "nimbus/math/box.h"
#include "nimbus/math/rng.h"

namespace nimbus {
namespace quadric_test {

Vec3 random_point(Rng& rng, double r) {
  return {r * (2 * rng.uniform() - 1), r * (2 * rng.uniform() - 1), r * (2 * rng.uniform() - 1)};
}

TEST(Quadric, MatrixRoundTripKeepsCoefficients) {
  const Quadric q{{1, -2, 3, 0.5, -0.25, 4, 1.5, -1, 2, -7}};
  const Quadric r = from_matrix(to_matrix(q));
  for (int i = 0; i < 10; ++i) EXPECT_DOUBLE_EQ(q.a[i], r.a[i]) << i;
}

TEST(Quadric, TransformActsOnCoefficientsOnly) {
  Rng rng(1);
  for (int trial = 0; trial < 200; ++trial) {
    Quadric q;
    for (double& c : q.a) c = 2 * rng.uniform() - 1;
    const Mat4 M = Mat4::translate(random_point(rng, 3)) *
                   Mat4::rotate(random_point(rng, 1) + Vec3{0.1, 0, 0}, 360 * rng.uniform()) *
                   Mat4::scale({0.5 + rng.uniform(), 0.5 + rng.uniform(), 0.5 + rng.uniform()});
    const Quadric qm = transformed(q, M);
    for (int k = 0; k < 20; ++k) {
      const Vec3 x = random_point(rng, 2);
      const double expect = q.eval(x);
      EXPECT_NEAR(qm.eval(transform_point(M, x)), expect, 1e-9 * (1 + std::abs(expect)));
    }
  }
}

TEST(Quadric, GradientMatchesFiniteDifferences) {
  Rng rng(2);
  Quadric q;
  for (double& c : q.a) c = 2 * rng.uniform() - 1;
  for (int k = 0; k < 100; ++k) {
    const Vec3 x = random_point(rng, 2);
    const Vec3 g = q.gradient(x);
    const double h = 1e-6;
    for (int i = 0; i < 3; ++i) {
      Vec3 a = x, b = x;
      a[i] += h;
      b[i] -= h;
      EXPECT_NEAR(g[i], (q.eval(a) - q.eval(b)) / (2 * h), 1e-6);
    }
  }
}

TEST(Quadric, RestrictionToRayIsExact) {
  Rng rng(3);
  Quadric q;
  for (double& c : q.a) c = 2 * rng.uniform() - 1;
  const Ray r{random_point(rng, 2), random_point(rng, 1)};
  const RayQuadratic p = restrict_to_ray(q, r);
  for (double t : {-2.0, -0.3, 0.0, 0.7, 3.1}) EXPECT_NEAR(p.at(t), q.eval(r.at(t)), 1e-12);
}

TEST(Primitives, SurfacesPassThroughParameterPoints) {
  const Vec3 c{0.3, -1.2, 2.0};
  const double eps = 1e-12;
  // Sphere: c ± r e_i on the surface, centre inside.
  const Quadric s = sphere(c, 1.5);
  EXPECT_NEAR(s.eval(c + Vec3{1.5, 0, 0}), 0, eps);
  EXPECT_NEAR(s.eval(c + Vec3{0, 0, -1.5}), 0, eps);
  EXPECT_GT(s.eval(c), 0);
  // Ellipsoid: c ± r_i e_i.
  const Quadric e = ellipsoid(c, {0.5, 2, 3});
  EXPECT_NEAR(e.eval(c + Vec3{0.5, 0, 0}), 0, eps);
  EXPECT_NEAR(e.eval(c + Vec3{0, -2, 0}), 0, eps);
  EXPECT_NEAR(e.eval(c + Vec3{0, 0, 3}), 0, eps);
  EXPECT_GT(e.eval(c), 0);
  // Cylinder along a tilted axis: p + s a + r u for u ⊥ a, any s.
  const Vec3 a = normalize(Vec3{1, 1, 0}), u{0, 0, 1};
  const Quadric cy = cylinder(c, a, 0.7);
  for (double sa : {-5.0, 0.0, 3.0}) EXPECT_NEAR(cy.eval(c + sa * a + 0.7 * u), 0, 1e-11);
  EXPECT_GT(cy.eval(c + 10.0 * a), 0);
  // Cone: apex and points at angle θ from the axis.
  const Quadric co = cone(c, {0, 1, 0}, 30);
  EXPECT_NEAR(co.eval(c), 0, eps);
  EXPECT_NEAR(co.eval(c + Vec3{std::tan(M_PI / 6), 1, 0} * 2.0), 0, 1e-11);
  EXPECT_GT(co.eval(c + Vec3{0, 1, 0}), 0);
  EXPECT_GT(co.eval(c + Vec3{0, -1, 0}), 0);
  // Paraboloid r² = 4 f h.
  const Quadric pa = paraboloid(c, {0, 0, 1}, 0.25);
  EXPECT_NEAR(pa.eval(c + Vec3{1, 0, 1}), 0, eps);
  EXPECT_NEAR(pa.eval(c), 0, eps);
  EXPECT_GT(pa.eval(c + Vec3{0, 0, 1}), 0);
  // Half-space: the point is on the plane, the normal points out.
  const Quadric h = halfspace(c, {0, 2, 0});
  EXPECT_NEAR(h.eval(c + Vec3{4, 0, -1}), 0, eps);
  EXPECT_LT(h.eval(c + Vec3{0, 1, 0}), 0);
  // Slab: both planes at ±w/2.
  const Quadric sl = slab(c, {0, 0, 1}, 0.4);
  EXPECT_NEAR(sl.eval(c + Vec3{3, 1, 0.2}), 0, eps);
  EXPECT_NEAR(sl.eval(c + Vec3{-1, 0, -0.2}), 0, eps);
  EXPECT_GT(sl.eval(c), 0);
}

}  // namespace quadric_test
}  // namespace nimbus

namespace nimbus {
namespace quadric_test {

TEST(Box, ClipRayMissesAnEmptyBox) {
  double t0 = 0, t1 = 10;
  EXPECT_FALSE(clip_ray(Box{}, Ray{{0, 0, 0}, {1, 0, 0}}, t0, t1));
  t0 = 0, t1 = 10;
  EXPECT_TRUE(clip_ray(Box{{-1, -1, -1}, {1, 1, 1}}, Ray{{-5, 0, 0}, {1, 0, 0}}, t0, t1));
  EXPECT_DOUBLE_EQ(t0, 4);
  EXPECT_DOUBLE_EQ(t1, 6);
}

}  // namespace quadric_test
}  // namespace nimbus
