#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

#include "frep_gallery.h"
#include "nimbus/frep/tape.h"

namespace nimbus {
namespace frep_tape_test {

using test::gallery;
using test::leaf;
using test::random_affine;
using test::random_in_cube;

double cube_pos(double x) {
  return x > 0 ? x * x * x : 0.0;
}

TEST(Tape, ClassifiesShapes) {
  EXPECT_EQ(compile(*leaf(sphere({0, 0, 0}, 1))).kind, TapeKind::SingleQuadric);
  // A one-child CSG is just its child.
  EXPECT_EQ(compile(*make_shape(CsgNode{CsgOp::Union, {leaf(sphere({0, 0, 0}, 1))}})).kind,
            TapeKind::SingleQuadric);
  Rng rng(1);
  const Tape flat = compile(*test::bumpy_sphere(rng, 8));
  EXPECT_EQ(flat.kind, TapeKind::FlatFreeForm);
  EXPECT_EQ(flat.weights.size(), 8u);
  EXPECT_EQ(flat.quadrics.size(), 9u);
  // Transforms anywhere keep a free form flat: they fold into the coefficients.
  FreeFormNode moved{leaf(sphere({0, 0, 0}, 1), Mat4::scale({2, 1, 1})),
                     {{leaf(sphere({1, 0, 0}, 0.5), Mat4::rotate({0, 0, 1}, 30)), 3.0}}};
  EXPECT_EQ(compile(*make_shape(std::move(moved), Mat4::translate({1, 2, 3}))).kind,
            TapeKind::FlatFreeForm);
  for (const auto& g : gallery()) {
    const Tape tape = compile(*g.shape);
    if (g.name == "clipped_cylinder" || g.name == "csg_difference" || g.name == "box") {
      EXPECT_EQ(tape.kind, TapeKind::QuadricCsg) << g.name;
    }
    if (g.name == "nested_free_form" || g.name == "csg_union") {
      EXPECT_EQ(tape.kind, TapeKind::General) << g.name;
    }
    EXPECT_LE(tape.num_registers, kMaxRegisters);
  }
  // More perturbations than the flat path holds fall back to the general one.
  EXPECT_EQ(compile(*test::bumpy_sphere(rng, kMaxFlatPerturbations + 1)).kind, TapeKind::General);
}

TEST(Tape, ZeroWeightPerturbationsAreDropped) {
  FreeFormNode ff{leaf(sphere({0, 0, 0}, 1)), {{leaf(sphere({1, 0, 0}, 0.5)), 0.0}}};
  const Tape tape = compile(*make_shape(std::move(ff)));
  EXPECT_EQ(tape.kind, TapeKind::SingleQuadric);
}

TEST(Tape, RejectsNullAndEmptyNodes) {
  EXPECT_THROW(compile(*make_shape(CsgNode{CsgOp::Union, {}})), std::invalid_argument);
  EXPECT_THROW(compile(*make_shape(CsgNode{CsgOp::Union, {nullptr}})), std::invalid_argument);
  EXPECT_THROW(compile(*make_shape(FreeFormNode{nullptr, {}})), std::invalid_argument);
  EXPECT_THROW(compile(*make_shape(FreeFormNode{leaf(sphere({0, 0, 0}, 1)), {{nullptr, 1.0}}})),
               std::invalid_argument);
  ShapePtr deep = leaf(sphere({0, 0, 0}, 1));
  for (int i = 0; i < kMaxRegisters; ++i)
    deep = make_shape(FreeFormNode{leaf(sphere({0, 0, 0}, 1)), {{deep, 1.0}}});
  EXPECT_THROW(compile(*deep), std::invalid_argument);
}

// Eq. 1–2 and the CSG rules written out directly against the description's quadrics.
TEST(Tape, EvaluatesFreeFormsAndCsgByTheirDefinitions) {
  const Quadric base = ellipsoid({0, 0, 0}, {1, 0.7, 0.5});
  const Quadric p1 = sphere({0.8, 0, 0}, 0.4), p2 = sphere({0, 0.5, 0.2}, 0.3);
  const Quadric p3 = cylinder({0, 0, 0}, {0, 0, 1}, 0.2);
  FreeFormNode inner{leaf(p2), {{leaf(p3), -4.0}}};
  FreeFormNode outer{leaf(base), {{leaf(p1), 50.0}, {make_shape(std::move(inner)), 2.0}}};
  const ShapePtr ff = make_shape(std::move(outer));
  const ShapePtr diff = make_shape(CsgNode{CsgOp::Difference, {ff, leaf(p1), leaf(p3)}});
  const ShapePtr uni = make_shape(CsgNode{CsgOp::Union, {leaf(p1), leaf(p2), leaf(p3)}});
  const ShapePtr inter = make_shape(CsgNode{CsgOp::Intersection, {leaf(p1), leaf(p2)}});
  const Tape t_ff = compile(*ff), t_diff = compile(*diff), t_uni = compile(*uni),
             t_inter = compile(*inter);
  Rng rng(3);
  for (int i = 0; i < 2000; ++i) {
    const Vec3 x = random_in_cube(rng, 1.5);
    const double f_inner = p2.eval(x) - 4.0 * cube_pos(p3.eval(x));
    const double f_ff = base.eval(x) + 50.0 * cube_pos(p1.eval(x)) + 2.0 * cube_pos(f_inner);
    EXPECT_NEAR(evaluate(t_ff, x), f_ff, 1e-12 * (1 + std::abs(f_ff)));
    EXPECT_NEAR(evaluate(t_diff, x), std::min({f_ff, -p1.eval(x), -p3.eval(x)}),
                1e-12 * (1 + std::abs(f_ff)));
    EXPECT_DOUBLE_EQ(evaluate(t_uni, x), std::max({p1.eval(x), p2.eval(x), p3.eval(x)}));
    EXPECT_DOUBLE_EQ(evaluate(t_inter, x), std::min(p1.eval(x), p2.eval(x)));
  }
}

TEST(Tape, GradientMatchesCentralDifferences) {
  Rng rng(4);
  for (const auto& g : gallery()) {
    const Tape tape = compile(*g.shape);
    int checked = 0;
    for (int i = 0; i < 400; ++i) {
      const Vec3 x = g.centre + random_in_cube(rng, g.radius);
      const double h = 1e-6;
      Vec3 fd;
      bool smooth = true;
      for (int k = 0; k < 3; ++k) {
        Vec3 a = x, b = x;
        a[k] += h;
        b[k] -= h;
        const double fa = evaluate(tape, a), fb = evaluate(tape, b), f0 = evaluate(tape, x);
        fd[k] = (fa - fb) / (2 * h);
        // Skip points next to a CSG crease, where the one-sided slopes differ.
        smooth &= std::abs((fa - f0) - (f0 - fb)) < 1e-6 * (1 + std::abs(f0));
      }
      if (!smooth) continue;
      ++checked;
      const Vec3 grad = gradient(tape, x);
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(grad[k], fd[k], 1e-5 * (1 + length(fd))) << g.name << " axis " << k;
    }
    EXPECT_GT(checked, 300) << g.name;
  }
}

TEST(Tape, GradientPointsInward) {
  const Tape tape = compile(*leaf(sphere({1, 2, 3}, 2)));
  const Vec3 g = gradient(tape, {3, 2, 3});  // on the surface, +x side
  EXPECT_LT(g.x, 0);
  EXPECT_NEAR(g.y, 0, 1e-12);
}

// F_transformed(M x) = F(x) for random translate/rotate/scale compositions of every shape.
TEST(Tape, TransformsMoveTheShape) {
  Rng rng(5);
  for (const auto& g : gallery()) {
    const Tape plain = compile(*g.shape);
    for (int trial = 0; trial < 10; ++trial) {
      const Mat4 m = random_affine(rng) * random_affine(rng);
      const Tape moved = compile(*with_transform(g.shape, m));
      for (int i = 0; i < 100; ++i) {
        const Vec3 x = g.centre + random_in_cube(rng, g.radius);
        const double f = evaluate(plain, x);
        ASSERT_NEAR(evaluate(moved, transform_point(m, x)), f, 1e-8 * (1 + std::abs(f))) << g.name;
      }
    }
  }
}

// A transformed free form with transformed children: each leaf sees the point mapped back
// through its own chain of transforms.
TEST(Tape, TreeTransformsCompose) {
  Rng rng(6);
  for (int trial = 0; trial < 50; ++trial) {
    const Mat4 m_ff = random_affine(rng), m_base = random_affine(rng), m_p = random_affine(rng),
               m_inner = random_affine(rng), m_q = random_affine(rng);
    const Quadric base = ellipsoid({0, 0, 0}, {1, 0.7, 0.5}), p = sphere({0.5, 0, 0}, 0.6),
                  q = sphere({0, 0.2, 0}, 0.5);
    FreeFormNode inner{leaf(q, m_q), {}};
    FreeFormNode ff{leaf(base, m_base),
                    {{leaf(p, m_p), 3.0}, {make_shape(std::move(inner), m_inner), -2.0}}};
    const Tape tape = compile(*make_shape(std::move(ff), m_ff));
    const Mat4 to_base = inverse(m_ff * m_base), to_p = inverse(m_ff * m_p),
               to_q = inverse(m_ff * m_inner * m_q);
    for (int i = 0; i < 50; ++i) {
      const Vec3 x = random_in_cube(rng, 3);
      const double f = base.eval(transform_point(to_base, x)) +
                       3.0 * cube_pos(p.eval(transform_point(to_p, x))) -
                       2.0 * cube_pos(q.eval(transform_point(to_q, x)));
      ASSERT_NEAR(evaluate(tape, x), f, 1e-8 * (1 + std::abs(f)));
    }
  }
}

TEST(Tape, IsCopyableAndEvaluatesTheSameAfterCopy) {
  const auto shapes = gallery();
  const Tape original = compile(*shapes[5].shape);
  const Tape copy = original;  // NOLINT(performance-unnecessary-copy-initialization)
  const Vec3 x{0.3, 0.9, -0.2};
  EXPECT_EQ(evaluate(copy, x), evaluate(original, x));
}

}  // namespace frep_tape_test
}  // namespace nimbus
