// Free forms at the ends of the scene format's documented ranges (issue 44): a perturbation of
// radius 1e100 with weight ±1e15 made F NaN (1e200 cubed overflows: +inf − inf), and the render
// dropped those samples. Every primitive, at its extremes, as base and as perturbations of both
// signs: F at a point, over a box and along a ray, and its gradient, are never NaN.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "nimbus/frep/intersect.h"
#include "nimbus/frep/primitives.h"
#include "nimbus/frep/tape.h"

namespace nimbus {
namespace frep_extremes_test {

constexpr double kBig = 1e100, kSmall = 1e-100, kWeight = 1e15;

struct Named {
  std::string name;
  ShapePtr shape;
};

ShapePtr leaf(const Quadric& q) {
  return make_shape(QuadricNode{q});
}

// Each primitive with its parameters at the ends of their ranges (docs/scene-format.md):
// coordinates and lengths in [1e-100, 1e100], angles in (0, 90), quadric coefficients finite.
std::vector<Named> extremes() {
  const double huge = 1e308;
  return {
      {"sphere r=1e100", leaf(sphere({0, 0, 0}, kBig))},
      {"sphere r=1e100 at 1e100", leaf(sphere({kBig, kBig, -kBig}, kBig))},
      {"sphere r=1e-100", leaf(sphere({0, 0, 0}, kSmall))},
      {"ellipsoid", leaf(ellipsoid({0, 0, 0}, {kBig, kSmall, 1}))},
      {"cylinder", leaf(cylinder({kBig, 0, 0}, {0, 0, 1}, kBig))},
      {"cone wide", leaf(cone({0, 0, 0}, {0, 0, 1}, 89.999999))},
      {"cone narrow", leaf(cone({-kBig, 0, 0}, {1, 0, 0}, 1e-6))},
      {"paraboloid f=1e100", leaf(paraboloid({0, 0, 0}, {0, 0, 1}, kBig))},
      {"paraboloid f=1e-100", leaf(paraboloid({0, 0, -kBig}, {0, 0, 1}, kSmall))},
      {"halfspace", leaf(halfspace({kBig, 0, 0}, {1, 0, 0}))},
      {"slab", leaf(slab({0, 0, 0}, {1, 1, 0}, kBig))},
      {"box", box({-kBig, -kBig, -kBig}, {kBig, kBig, kBig})},
      {"quadric 1e308", leaf(Quadric{{-huge, -huge, huge, huge, 0, 0, huge, 0, 0, huge}})},
  };
}

// A free form of `base` with the perturbation `p` added with weight +1e15 and carved with −1e15
// (so that two overflowing terms meet), and that free form nested as a perturbation again.
std::vector<Tape> free_forms(const ShapePtr& base, const ShapePtr& p) {
  const ShapePtr ff = make_shape(FreeFormNode{base, {{p, kWeight}, {p, -kWeight}}});
  const ShapePtr nested = make_shape(FreeFormNode{leaf(sphere({0, 0, 0}, 1)), {{ff, -kWeight}}});
  const ShapePtr mixed = make_shape(FreeFormNode{p, {{leaf(sphere({0, 0, 0}, 1)), kWeight}}});
  return {compile(*ff), compile(*nested), compile(*mixed)};
}

TEST(FrepExtremes, FreeFormsAtTheDocumentedRangesAreNeverNaN) {
  const std::vector<Vec3> points = {{0, 0, 0},    {0.5, 0.25, 0},      {1e50, -1e50, 1e50},
                                    {kBig, 0, 0}, {kBig, kBig, -kBig}, {-kBig, -kBig, -kBig},
                                    {0, 0, -kBig}};
  const std::vector<Box> boxes = {
      Box{{-1, -1, -1}, {1, 1, 1}}, Box{{-kBig, -kBig, -kBig}, {kBig, kBig, kBig}},
      Box{{0.999 * kBig, -1, -1}, {kBig, 1, 1}}, Box{{-1e-3, -1e-3, -1e-3}, {1e-3, 1e-3, 1e-3}}};
  const std::vector<Ray> rays = {Ray{{0, 0, 5}, {0, 0, -1}}, Ray{{0.3, 0.2, -5}, {0, 0, 1}},
                                 Ray{{kBig, kBig, -kBig}, {-1, -1, 1}},
                                 Ray{{-2 * kBig, 0, 0}, {1, 0, 0}}};
  const std::vector<Named> shapes = extremes();
  int checked = 0;
  for (const Named& base : {Named{"unit sphere", leaf(sphere({0, 0, 0}, 1))}, shapes[0]})
    for (const Named& p : shapes) {
      const std::string where = base.name + " + " + p.name;
      for (const Tape& t : free_forms(base.shape, p.shape)) {
        for (const Vec3& x : points) {
          EXPECT_FALSE(std::isnan(evaluate(t, x))) << where;
          const Vec3 g = gradient(t, x);
          EXPECT_FALSE(std::isnan(g.x) || std::isnan(g.y) || std::isnan(g.z)) << where;
          ++checked;
        }
        for (const Box& b : boxes) {
          const Interval f = evaluate(t, b);
          EXPECT_FALSE(std::isnan(f.lo) || std::isnan(f.hi)) << where;
          EXPECT_LE(f.lo, f.hi) << where;
        }
        for (const Ray& r : rays) {
          const auto hit = first_hit(t, r, 0, 4 * kBig);
          EXPECT_FALSE(hit && std::isnan(*hit)) << where;
        }
      }
    }
  EXPECT_GT(checked, 500);
}

}  // namespace frep_extremes_test
}  // namespace nimbus
