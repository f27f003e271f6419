// An object's stretches inside its medium along a ray (media/medium_field.h): where F > 0, found
// for a single quadric from both its roots at once and for any other shape by first_hit root
// after root. Both are checked against F sampled along the ray and against each other.

#include "nimbus/media/medium_field.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "frep_gallery.h"
#include "nimbus/frep/primitives.h"
#include "nimbus/frep/tape.h"

namespace nimbus {
namespace medium_field_test {

struct Named {
  std::string name;
  Quadric quadric;
};

// Every kind of quadric the scene format has; along some rays the cone's two nappes make two
// stretches.
std::vector<Named> quadrics() {
  return {{"sphere", sphere({0.2, -0.1, 0.3}, 1.2)},
          {"ellipsoid", ellipsoid({0, 0, 0}, {1.5, 0.6, 1})},
          {"cylinder", cylinder({0.1, 0, 0}, {0.3, 1, 0.2}, 0.7)},
          {"cone", cone({0, 0.2, 0}, {1, 0.5, 0}, 50)},
          {"paraboloid", paraboloid({0, -1, 0}, {0, 1, 0.3}, 0.4)},
          {"halfspace", halfspace({0, 0.3, 0}, {0.2, 1, 0})},
          {"slab", slab({0, 0, 0}, {0.3, 0.2, 1}, 0.8)}};
}

// The same quadric compiled to the general path: a far-away nested perturbation changes nothing
// near it (as in FirstHit.FastPathsAgreeWithTheGeneralPath).
Tape general_tape(const ShapePtr& shape) {
  const ShapePtr far_away = make_shape(FreeFormNode{test::leaf(sphere({100, 0, 0}, 1)),
                                                    {{test::leaf(sphere({100, 1, 0}, 1)), 1.0}}});
  return compile(*make_shape(FreeFormNode{shape, {{far_away, 1.0}}}));
}

bool inside(const MediumIntervals& m, double t) {
  for (int i = 0; i < m.count; ++i)
    if (t >= m.spans[i].t0 && t <= m.spans[i].t1) return true;
  return false;
}

TEST(ObjectSpans, OneQuadricAgreesWithTheSampledFieldAndTheGeneralPath) {
  const Box bounds{{-3, -3, -3}, {3, 3, 3}};
  Rng rng(5);
  for (const Named& q : quadrics()) {
    const ShapePtr shape = test::leaf(q.quadric, test::random_rigid(rng, 0.5));
    const Tape fast = compile(*shape), general = general_tape(shape);
    ASSERT_EQ(fast.kind, TapeKind::SingleQuadric) << q.name;
    ASSERT_EQ(general.kind, TapeKind::General) << q.name;
    int two_spans = 0, sampled = 0;
    for (int i = 0; i < 2000; ++i) {
      const Ray ray{test::random_in_cube(rng, 4), test::random_unit(rng) * (0.5 + rng.uniform())};
      const double t0 = 0.5 * rng.uniform(), t1 = t0 + 12 * rng.uniform();
      MediumIntervals a, b;
      ASSERT_TRUE(add_object_spans(fast, bounds, ray, t0, t1, a));
      ASSERT_TRUE(add_object_spans(general, bounds, ray, t0, t1, b));
      ASSERT_EQ(a.count, b.count) << q.name << " ray " << i;
      for (int s = 0; s < a.count; ++s) {
        EXPECT_NEAR(a.spans[s].t0, b.spans[s].t0, 1e-8) << q.name << " ray " << i;
        EXPECT_NEAR(a.spans[s].t1, b.spans[s].t1, 1e-8) << q.name << " ray " << i;
      }
      two_spans += a.count == 2;
      // Inside the bounds, F's sign away from the surface decides membership (the ends are left
      // out: the clipped ends there are rounded).
      double c0 = t0, c1 = t1;
      if (!clip_ray(bounds, ray, c0, c1)) continue;
      for (int k = 1; k < 50; ++k) {
        const double t = c0 + (c1 - c0) * k / 50.0;
        const double F = evaluate(fast, ray.at(t));
        if (std::abs(F) < 1e-6) continue;
        ++sampled;
        EXPECT_EQ(inside(a, t), F > 0) << q.name << " ray " << i << " t " << t;
      }
    }
    EXPECT_GT(sampled, 10000) << q.name;
    if (q.name == "cone") {
      EXPECT_GT(two_spans, 15);
    }
  }
}

// The union of closed intervals, sorted, with touching ones joined: the reference for add_span.
std::vector<Span> merged(std::vector<Span> all) {
  std::sort(all.begin(), all.end(), [](const Span& x, const Span& y) { return x.t0 < y.t0; });
  std::vector<Span> out;
  for (const Span& s : all)
    if (!out.empty() && s.t0 <= out.back().t1)
      out.back().t1 = std::max(out.back().t1, s.t1);
    else
      out.push_back(s);
  return out;
}

TEST(ObjectSpans, AddSpanKeepsTheSortedUnionAndRefusesOverflowUnchanged) {
  Rng rng(9);
  int refused = 0, merges = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    MediumIntervals m;
    std::vector<Span> added;
    const int n = 1 + int(rng.uniform() * 80);
    for (int k = 0; k < n; ++k) {
      // Endpoints on a coarse grid, so that spans often touch exactly.
      const double a = std::floor(rng.uniform() * 800) / 4,
                   b = a + std::floor(rng.uniform() * 8) / 4;
      const MediumIntervals before = m;
      std::vector<Span> with = added;
      with.push_back({a, b});
      const std::vector<Span> expected = merged(with);
      if (!add_span(m, a, b)) {
        ASSERT_GT(expected.size(), std::size_t(MediumIntervals::kMax)) << trial;
        ASSERT_EQ(m.count, before.count);
        for (int i = 0; i < m.count; ++i) {
          ASSERT_EQ(m.spans[i].t0, before.spans[i].t0);
          ASSERT_EQ(m.spans[i].t1, before.spans[i].t1);
        }
        ++refused;
        continue;
      }
      added = with;
      merges += int(expected.size()) < before.count + 1;  // [a, b] joined a span
      ASSERT_EQ(m.count, int(expected.size())) << trial << " " << k;
      for (int i = 0; i < m.count; ++i) {
        ASSERT_EQ(m.spans[i].t0, expected[i].t0) << trial << " " << k;
        ASSERT_EQ(m.spans[i].t1, expected[i].t1) << trial << " " << k;
      }
    }
  }
  EXPECT_GT(refused, 1000);
  EXPECT_GT(merges, 10000);
}

}  // namespace medium_field_test
}  // namespace nimbus
