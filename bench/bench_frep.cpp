// Ray casting throughput of compiled FRep shapes: rays per second for a pinhole camera's pixel
// grid framing the object with a margin, so a realistic mix of hits and misses.

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "nimbus/frep/intersect.h"
#include "nimbus/frep/primitives.h"
#include "nimbus/frep/tape.h"
#include "nimbus/math/rng.h"

namespace nimbus {
namespace {

ShapePtr leaf(const Quadric& q) {
  return make_shape(QuadricNode{q});
}

Vec3 random_unit(Rng& rng) {
  const double z = 2 * rng.uniform() - 1, phi = 2 * M_PI * rng.uniform();
  const double r = std::sqrt(1 - z * z);
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// A unit sphere with `count` bumps and dents of radius 0.15–0.5 on its surface.
ShapePtr bumpy_sphere(int count) {
  Rng rng(7);
  FreeFormNode ff{leaf(sphere({0, 0, 0}, 1)), {}};
  for (int i = 0; i < count; ++i) {
    const double r = 0.15 + 0.35 * rng.uniform();
    const double sign = i % 3 == 1 ? -1.0 : 1.0;
    ff.perturbations.push_back({leaf(sphere(random_unit(rng), r)), sign * 0.5 / std::pow(r, 6)});
  }
  return make_shape(std::move(ff));
}

ShapePtr nested_free_form() {
  FreeFormNode inner{leaf(ellipsoid({0.9, 0, 0}, {0.5, 0.3, 0.3})),
                     {{leaf(sphere({1.3, 0, 0}, 0.2)), 0.5 / std::pow(0.2, 6)}}};
  FreeFormNode outer{bumpy_sphere(8), {{make_shape(std::move(inner)), 0.7}}};
  return make_shape(std::move(outer), Mat4::rotate({1, 0, 0}, 25));
}

ShapePtr csg_box() {
  CsgNode diff{
      CsgOp::Difference,
      {with_transform(box({-0.8, -0.8, -0.8}, {0.8, 0.8, 0.8}), Mat4::rotate({1, 1, 0}, 30)),
       leaf(sphere({0, 0, 0}, 1.0))}};
  return make_shape(std::move(diff));
}

// Eye rays of a 128 × 128 camera 4 units away, seeing a 3 × 3 window around the origin, from
// eight viewpoints.
std::vector<Ray> camera_rays() {
  std::vector<Ray> rays;
  Rng rng(3);
  for (int view = 0; view < 8; ++view) {
    const Vec3 eye = 4.0 * random_unit(rng);
    const Vec3 forward = normalize(-eye);
    Vec3 right, up;
    orthonormal_basis(forward, right, up);
    for (int y = 0; y < 128; ++y)
      for (int x = 0; x < 128; ++x) {
        const double u = 1.5 * ((x + 0.5) / 64 - 1), v = 1.5 * ((y + 0.5) / 64 - 1);
        rays.push_back({eye, normalize(forward * 4.0 + right * u + up * v)});
      }
  }
  return rays;
}

void cast(benchmark::State& state, const ShapePtr& shape) {
  const Tape tape = compile(*shape);
  const std::vector<Ray> rays = camera_rays();
  size_t hits = 0;
  for (auto _ : state) {
    hits = 0;
    for (const Ray& ray : rays) {
      const auto t = first_hit(tape, ray, 0, 1e30);
      hits += t.has_value();
      benchmark::DoNotOptimize(t);
    }
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * rays.size()));
  state.counters["hit_fraction"] = static_cast<double>(hits) / rays.size();
}

void BM_Sphere(benchmark::State& s) {
  cast(s, leaf(sphere({0, 0, 0}, 1)));
}
void BM_FreeForm1(benchmark::State& s) {
  cast(s, bumpy_sphere(1));
}
void BM_FreeForm8(benchmark::State& s) {
  cast(s, bumpy_sphere(8));
}
void BM_FreeForm32(benchmark::State& s) {
  cast(s, bumpy_sphere(32));
}
void BM_NestedFreeForm(benchmark::State& s) {
  cast(s, nested_free_form());
}
void BM_CsgBox(benchmark::State& s) {
  cast(s, csg_box());
}

BENCHMARK(BM_Sphere)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FreeForm1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FreeForm8)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FreeForm32)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NestedFreeForm)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CsgBox)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace nimbus

BENCHMARK_MAIN();
