// Interval evaluation of tapes over boxes must enclose every point value inside the box.

#include <gtest/gtest.h>

#include <cmath>

#include "frep_gallery.h"
#include "nimbus/frep/primitives.h"
#include "nimbus/frep/tape.h"
#include "nimbus/frep/tape_eval.h"

namespace nimbus {
namespace frep_interval_test {

using test::leaf;
using test::random_in_cube;

// 1000 random boxes (centres around the shape, half-widths from 10⁻⁴ to 1 of its size, per
// axis) × 100 random points each: 10⁵ point values per shape.
void expect_enclosed(const std::string& name, const ShapePtr& shape, const Vec3& centre,
                     double radius, uint64_t seed) {
  const Tape tape = compile(*shape);
  Rng rng(seed);
  for (int b = 0; b < 1000; ++b) {
    const Vec3 c = centre + random_in_cube(rng, 1.2 * radius);
    Vec3 half;
    for (int i = 0; i < 3; ++i) half[i] = radius * std::pow(10.0, -4 * rng.uniform());
    const Box box{c - half, c + half};
    const Interval range = evaluate(tape, box);
    ASSERT_LE(range.lo, range.hi) << name;
    for (int k = 0; k < 100; ++k) {
      Vec3 x;
      for (int i = 0; i < 3; ++i) x[i] = box.lo[i] + (box.hi[i] - box.lo[i]) * rng.uniform();
      const double f = evaluate(tape, x);
      ASSERT_TRUE(range.contains(f))
          << name << ": F = " << f << " outside [" << range.lo << ", " << range.hi << "]";
    }
  }
}

TEST(TapeInterval, EnclosesPrimitives) {
  const Mat4 m = Mat4::translate({0.3, -0.2, 0.1}) * Mat4::rotate({1, 2, 3}, 40);
  const struct {
    const char* name;
    Quadric q;
  } primitives[] = {
      {"sphere", sphere({0, 0, 0}, 1)},
      {"ellipsoid", ellipsoid({0, 0, 0}, {1, 0.5, 0.3})},
      {"cylinder", cylinder({0, 0, 0}, {1, 1, 0}, 0.5)},
      {"cone", cone({0, 0, 0}, {0, 0, 1}, 25)},
      {"paraboloid", paraboloid({0, 0, 0}, {0, 1, 0}, 0.3)},
      {"halfspace", halfspace({0, 0, 0}, {1, -1, 2})},
      {"slab", slab({0, 0, 0}, {0, 1, 1}, 0.4)},
  };
  uint64_t seed = 100;
  for (const auto& p : primitives)
    expect_enclosed(p.name, leaf(p.q, m), {0.3, -0.2, 0.1}, 1.0, seed++);
  expect_enclosed("box", with_transform(box({-1, -0.5, -0.2}, {1, 0.5, 0.2}), m), {0, 0, 0}, 1.0,
                  seed);
}

TEST(TapeInterval, EnclosesFreeFormsAndCsg) {
  uint64_t seed = 200;
  for (const auto& g : test::gallery())
    expect_enclosed(g.name, g.shape, g.centre, g.radius, seed++);
}

TEST(TapeInterval, ShrinksWithTheBox) {
  const auto width = [](const Tape& tape, const Vec3& c, double h) {
    const Interval r = evaluate(tape, Box{c - Vec3{h, h, h}, c + Vec3{h, h, h}});
    return r.hi - r.lo;
  };
  // One quadric: the centred form is exact to first order, width → 2 h Σ|∂F/∂x_i|.
  const Tape quadric =
      compile(*leaf(ellipsoid({0, 0, 0}, {1, 0.5, 0.3}), Mat4::rotate({1, 1, 0}, 30)));
  const Vec3 c{0.2, 0.1, -0.1};
  const Vec3 g = gradient(quadric, c);
  const double linear = 2e-5 * (std::abs(g.x) + std::abs(g.y) + std::abs(g.z));
  EXPECT_NEAR(width(quadric, c, 1e-5), linear, 1e-3 * linear);
  // A free form: sums of terms overestimate by a constant factor at most, so the width still
  // falls tenfold with the box.
  const auto shapes = test::gallery();
  const Tape bumpy = compile(*shapes[5].shape);
  const Vec3 p{0.2, 0.7, 0.5};
  EXPECT_NEAR(width(bumpy, p, 1e-5) / width(bumpy, p, 1e-4), 0.1, 0.002);
}

// A perturbation adds nothing over a box that misses the box of its positive set, although its
// centred form there reaches above 0 (by 0.47 here): skipping it keeps the interval tight and is
// what makes free forms with thousands of perturbations cheap to bound (issue 16).
TEST(TapeInterval, PerturbationsAwayFromTheBoxAddNothing) {
  const Quadric base_q = ellipsoid({0, 0, 0}, {3, 1, 1});
  const Quadric bump = sphere({2, 0, 0}, 0.5);
  const Box box{{0, -0.5, -0.5}, {1.45, 0.5, 0.5}};
  ASSERT_GT(quadric_range(bump, box).hi, 0.4);
  const Tape base = compile(*leaf(base_q));
  const Tape free_form = compile(*make_shape(FreeFormNode{leaf(base_q), {{leaf(bump), 5.0}}}));
  const Interval with = evaluate(free_form, box), without = evaluate(base, box);
  EXPECT_EQ(with.lo, without.lo);
  EXPECT_EQ(with.hi, without.hi);
  // Where the boxes meet, the perturbation counts.
  const Box touching{{1.4, -0.5, -0.5}, {1.6, 0.5, 0.5}};
  EXPECT_GT(evaluate(free_form, touching).hi, evaluate(base, touching).hi);
}

TEST(TapeInterval, InfiniteBoxIsEverything) {
  const Tape tape = compile(*leaf(sphere({0, 0, 0}, 1)));
  const Interval range = evaluate(tape, Box::everything());
  EXPECT_TRUE(std::isinf(range.lo) && std::isinf(range.hi));
}

}  // namespace frep_interval_test
}  // namespace nimbus
