// The surface index (issue 26): a bounding volume hierarchy over the objects with a surface and
// the sphere lights must give exactly what a walk down the list gives, the reference kept here:
// the same nearest surface at the same distance, bit for bit, ties to the surface listed first.

#include "nimbus/render/surface_index.h"

#include <gtest/gtest.h>

#include <functional>
#include <optional>
#include <set>
#include <vector>

#include "frep_gallery.h"
#include "nimbus/frep/intersect.h"
#include "nimbus/render/scene.h"
#include "support/scene_builders.h"

namespace nimbus {
namespace surface_index_test {

using test::random_in_cube;
using test::random_unit;

// The walk down the list: objects in scene order, then lights, each searched over its box's part
// of the ray's whole range; a hit replaces the nearest so far only when nearer, so among equal
// distances the surface listed first wins. (The walk before the hierarchy searched each object
// only up to the nearest hit so far, and a root search over a shorter range can round
// differently: in this test an object given twice was hit nearer, in the last bits, as its
// second copy.)
std::optional<SurfaceHit> intersect_by_list(const Scene& scene, const Ray& ray, double t_max) {
  std::optional<SurfaceHit> best;
  const double range = t_max;
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& obj = scene.objects[i];
    if (obj.surface.type == Surface::Type::None) continue;
    double t0 = 0, t1 = range;
    if (!clip_ray(obj.bounds, ray, t0, t1)) continue;
    if (auto t = first_hit(obj.tape, ray, t0, t1); t && (!best || *t < t_max)) {
      t_max = *t;
      best = SurfaceHit{*t, int(i), -1};
    }
  }
  for (size_t i = 0; i < scene.lights.size(); ++i)
    if (auto t = intersect_light(scene.lights[i], ray, 0, t_max)) {
      t_max = *t;
      best = SurfaceHit{*t, -1, int(i)};
    }
  return best;
}

bool occluded_by_list(const Scene& scene, const Ray& ray, double t_max, int target_light) {
  for (const SceneObject& obj : scene.objects) {
    if (obj.surface.type == Surface::Type::None) continue;
    double t0 = 0, t1 = t_max;
    if (clip_ray(obj.bounds, ray, t0, t1) && first_hit(obj.tape, ray, t0, t1)) return true;
  }
  for (size_t i = 0; i < scene.lights.size(); ++i)
    if (int(i) != target_light && intersect_light(scene.lights[i], ray, 0, t_max)) return true;
  return false;
}

Light sphere_light(const Vec3& center, double radius) {
  Light l;
  l.type = Light::Type::Sphere;
  l.center = center;
  l.radius = radius;
  l.emission = Rgb(1.0);
  return l;
}

// n objects in a cube of half-size `spread`: spheres, bumpy free forms (the flat path) and
// CSG (the general one), some media holders without a surface, a few sphere lights, and
// deliberate ties: an object given twice, a light on an object's very sphere.
Scene scattered_scene(int n, double spread, uint64_t seed, double scale = 1, Vec3 shift = {}) {
  Rng rng(seed, 3);
  Scene scene;
  const Mat4 place = Mat4::translate(shift) * Mat4::scale({scale, scale, scale});
  const auto placed = [&](const ShapePtr& shape) { return with_transform(shape, place); };
  const auto placed_light = [&](const Vec3& c, double r) {
    return sphere_light(transform_point(place, c), r * scale);
  };
  for (int i = 0; i < n; ++i) {
    const Vec3 c = random_in_cube(rng, spread);
    const double r = 0.05 + 0.4 * rng.uniform();
    ShapePtr shape;
    switch (i % 4) {
      case 0:
      case 1:
        shape = test::leaf(sphere(c, r));
        break;
      case 2:
        shape =
            with_transform(test::bumpy_sphere(rng, 3), Mat4::translate(c) * Mat4::scale({r, r, r}));
        break;
      default:
        shape = make_shape(
            CsgNode{CsgOp::Difference,
                    {test::leaf(sphere(c, r)), test::leaf(sphere(c + Vec3{r, 0, 0}, 0.6 * r))}});
    }
    const Surface::Type surface = i % 9 == 5   ? Surface::Type::None
                                  : i % 5 == 1 ? Surface::Type::Dielectric
                                               : Surface::Type::Diffuse;
    scene.objects.push_back(test::object_of(placed(shape), surface, -1));
    if (i % 13 == 0) scene.objects.push_back(scene.objects.back());  // a tie: the first wins
  }
  for (int i = 0; i < 1 + n / 50; ++i) {
    const Vec3 c = random_in_cube(rng, spread);
    scene.lights.push_back(placed_light(c, 0.1 + 0.3 * rng.uniform()));
  }
  scene.lights.push_back(test::environment(1));
  scene.lights.push_back(placed_light({0, 0, 0}, 0.3));  // on the object below: it wins the tie
  scene.objects.push_back(
      test::object_of(placed(test::leaf(sphere({0, 0, 0}, 0.3))), Surface::Type::Diffuse, -1));
  scene.surfaces = build_surface_index(scene.objects, scene.lights);
  return scene;
}

int depth_of(const SurfaceIndex& index, std::uint32_t at = 0) {
  const SurfaceNode& node = index.nodes[at];
  return node.count > 0 ? 0 : 1 + std::max(depth_of(index, at + 1), depth_of(index, node.index));
}

// Rays through the scene of scattered_scene (placed alike) against the walk down the list.
void expect_as_the_list(const Scene& scene, uint64_t seed, double spread, double scale = 1,
                        Vec3 shift = {}) {
  Rng rng(seed, 11);
  int hits = 0;
  for (int i = 0; i < 3000; ++i) {
    // From outside and from inside the cloud of objects, some from 10^4 times farther; some
    // directions along the axes, whose zero components the box tests must survive.
    Vec3 o = random_in_cube(rng, i % 2 ? 2 * spread : 0.5 * spread);
    if (i % 11 == 0) o = o * 1e4;
    Vec3 d = i % 7 == 0 ? Vec3{0, 0, rng.uniform() < 0.5 ? 1.0 : -1.0} : random_unit(rng);
    if (i % 3 == 0) d = normalize(random_in_cube(rng, 0.3 * spread) - o);
    const Ray ray{o * scale + shift, d};
    const double t_max = i % 5 == 0 ? spread * scale * rng.uniform() : Box::kInf;
    const auto expected = intersect_by_list(scene, ray, t_max);
    const auto got = intersect(scene, ray, t_max);
    ASSERT_EQ(got.has_value(), expected.has_value()) << "ray " << i;
    if (got) {
      ++hits;
      ASSERT_EQ(got->t, expected->t) << "ray " << i;
      ASSERT_EQ(got->object, expected->object) << "ray " << i;
      ASSERT_EQ(got->light, expected->light) << "ray " << i;
    }
    const int target = i % 4 == 0 ? int(scene.lights.size()) - 1 : -1;
    ASSERT_EQ(occluded(scene, ray, t_max, target), occluded_by_list(scene, ray, t_max, target))
        << "ray " << i;
  }
  EXPECT_GT(hits, 400);  // the rays do meet surfaces
}

TEST(SurfaceIndex, NearestHitsAreTheListsBitForBit) {
  for (const int n : {1, 7, 64, 400}) {
    const double spread = 0.5 * std::cbrt(double(n)) + 0.5;
    const Scene scene = scattered_scene(n, spread, uint64_t(n));
    expect_as_the_list(scene, uint64_t(n) + 100, spread);
  }
}

// Scenes far past a float's range or far below its resolution, and far from the origin, hit as
// the list does (the hierarchy's boxes and slabs are doubles).
TEST(SurfaceIndex, ScenesOfAnyScaleAndPlaceHitAsTheList) {
  const double spread = 0.5 * std::cbrt(200.0) + 0.5;
  for (const auto& [scale, shift] :
       {std::pair{1e45, Vec3{3e46, -1e46, 0}}, std::pair{1e-35, Vec3{0, 0, 0}},
        std::pair{1e-3, Vec3{1e4, 2e4, -3e4}}}) {
    SCOPED_TRACE(scale);
    const Scene scene = scattered_scene(200, spread, 17, scale, shift);
    ASSERT_GT(scene.surfaces.nodes.size(), 1u);
    // Far from the origin the smallest spheres fall below a double's resolution: empty, never
    // hit, and left out of the hierarchy (their NaN centroids had been binned).
    size_t empty = 0;
    for (const SceneObject& obj : scene.objects)
      empty += obj.surface.type != Surface::Type::None && obj.bounds.empty();
    EXPECT_EQ(scene.surfaces.entries.size() + empty,
              scene.surfaces.objects.size() + scene.surfaces.lights.size());
    expect_as_the_list(scene, 23, spread, scale, shift);
  }
}

// The solid a path starting at a point is in: the first dielectric object in scene order whose
// F is positive there, as a scan of every object finds it.
TEST(SurfaceIndex, TheSolidContainingAPointIsTheScansFirst) {
  for (const int n : {40, 400}) {
    const double spread = 0.5 * std::cbrt(double(n)) + 0.5;
    const Scene scene = scattered_scene(n, spread, uint64_t(n) + 7);
    Rng rng(uint64_t(n), 13);
    int inside = 0;
    for (int i = 0; i < 8000; ++i) {
      const Vec3 p = random_in_cube(rng, spread);
      int expected = -1;
      for (size_t k = 0; k < scene.objects.size() && expected < 0; ++k) {
        const SceneObject& obj = scene.objects[k];
        if (obj.surface.type == Surface::Type::Dielectric && obj.bounds.contains(p) &&
            evaluate(obj.tape, p) > 0)
          expected = int(k);
      }
      ASSERT_EQ(solid_containing(scene, p), expected) << "point " << i;
      inside += expected >= 0;
    }
    EXPECT_GT(inside, 20) << n;  // points do fall inside solids
  }
}

// Every surface once in the leaves, every box holding its children's, a bounded depth.
TEST(SurfaceIndex, TheHierarchyHoldsEverySurfaceOnce) {
  const Scene scene = scattered_scene(600, 4, 5);
  const SurfaceIndex& index = scene.surfaces;
  ASSERT_EQ(index.entries.size(), index.objects.size() + index.lights.size());
  std::multiset<std::uint32_t> seen(index.entries.begin(), index.entries.end());
  for (std::uint32_t e = 0; e < index.entries.size(); ++e) EXPECT_EQ(seen.count(e), 1u) << e;
  const auto entry_box = [&](std::uint32_t e) {
    return e < index.objects.size()
               ? scene.objects[index.objects[e]].bounds
               : surface_bounds(scene.lights[index.lights[e - index.objects.size()]]);
  };
  const auto inside = [](const Box& a, const Box& b) {
    return b.lo.x <= a.lo.x && b.lo.y <= a.lo.y && b.lo.z <= a.lo.z && a.hi.x <= b.hi.x &&
           a.hi.y <= b.hi.y && a.hi.z <= b.hi.z;
  };
  std::function<void(std::uint32_t)> walk = [&](std::uint32_t at) {
    const SurfaceNode& node = index.nodes[at];
    if (node.count > 0) {
      for (std::uint32_t k = 0; k < node.count; ++k)
        EXPECT_TRUE(inside(entry_box(index.entries[node.index + k]), node.bounds));
      return;
    }
    for (const std::uint32_t child : {at + 1, node.index}) {
      EXPECT_TRUE(inside(index.nodes[child].bounds, node.bounds));
      walk(child);
    }
  };
  walk(0);
  EXPECT_LT(depth_of(index), 40);
  // Coincident boxes cannot be told apart by the SAH; splits by count keep the depth bounded.
  std::vector<SceneObject> same(2000, scene.objects[0]);
  const SurfaceIndex stacked = build_surface_index(same, {});
  EXPECT_EQ(stacked.entries.size(), 2000u);
  EXPECT_LE(depth_of(stacked), 10);  // ⌈log2(2000 / 4)⌉ + 1
}

// A scene without surfaces has an empty index, and rays meet nothing.
TEST(SurfaceIndex, AnEmptySceneHitsNothing) {
  Scene scene;
  scene.lights.push_back(test::environment(1));
  scene.surfaces = build_surface_index(scene.objects, scene.lights);
  EXPECT_TRUE(scene.surfaces.nodes.empty());
  EXPECT_FALSE(intersect(scene, Ray{{0, 0, 0}, {0, 0, 1}}, Box::kInf));
  EXPECT_FALSE(occluded(scene, Ray{{0, 0, 0}, {0, 0, 1}}, Box::kInf));
}

}  // namespace surface_index_test
}  // namespace nimbus
