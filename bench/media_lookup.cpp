// The cost of a point's medium lookup (medium_at in the field) against the number of
// index-matched medium objects: N spherical puffs of radius 0.25 at a fixed number density,
// so that a point has the same few puffs around it whatever N (the region grows with N). Run:
//   build/media_lookup --benchmark_filter=Lookup
// Counters: lookups per second, the puffs present per lookup and the objects its cell lists.
// DependentLoad times this machine's memory: the floor under a lookup that misses the cache.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "nimbus/frep/bounds.h"
#include "nimbus/frep/primitives.h"
#include "nimbus/math/rng.h"
#include "nimbus/media/cloud_density.h"
#include "nimbus/media/medium_field.h"
#include "nimbus/render/path_spectra.h"
#include "nimbus/render/scene.h"
#include "nimbus/scene/compile.h"

namespace nimbus {
namespace {

constexpr double kRadius = 0.25;
constexpr double kPuffsPerVolume = 46;  // about three puffs hold a point of the region

struct Puffs {
  Scene scene;
  double side;  // the region is [0, side]³
};

Puffs make_puffs(int count, bool cloud) {
  Puffs p;
  p.side = std::cbrt(count / kPuffsPerVolume);
  Medium m;
  m.sigma_a = Rgb(0.1);
  m.sigma_s = Rgb({1.0, 2.0, 3.0});
  if (cloud) m.density = make_cloud_density(CloudParams{});
  p.scene.media.push_back(m);
  Rng rng(1);
  for (int i = 0; i < count; ++i) {
    const Vec3 c{p.side * rng.uniform(), p.side * rng.uniform(), p.side * rng.uniform()};
    SceneObject obj;
    obj.tape = compile(*make_shape(QuadricNode{sphere(c, kRadius)}));
    obj.bounds = compute_bounds(obj.tape).box;
    obj.surface.type = Surface::Type::None;
    obj.medium = 0;
    p.scene.objects.push_back(std::move(obj));
  }
  finish_scene(p.scene);
  return p;
}

// Lookups at random points of the region (`points` 0: each far from the last, as no tracker
// looks them up), in order along random chords of it, 0.02 apart (1: as a tracker steps through a
// medium of mu_bar 50, the objects it meets staying in cache), or along chords of a cube of side
// 1 at its centre (2: the same few dozen puffs met again and again, so that the lookup's data
// stays in cache whatever N; what is left is the lookup's own work).
std::vector<Vec3> lookup_points(double side, int mode) {
  std::vector<Vec3> points;
  Rng rng(2);
  const double cube = mode == 2 ? std::min(1.0, side) : side;
  const double lo = (side - cube) / 2;
  auto random_point = [&] {
    return Vec3{lo + cube * rng.uniform(), lo + cube * rng.uniform(), lo + cube * rng.uniform()};
  };
  while (points.size() < (1 << 16)) {
    if (mode == 0) {
      points.push_back(random_point());
      continue;
    }
    const Vec3 a = random_point(), b = random_point();
    const double length_ab = length(b - a);
    for (double t = 0; t < length_ab; t += 0.02) points.push_back(a + (b - a) * (t / length_ab));
  }
  return points;
}

void Lookup(benchmark::State& state) {
  const Puffs p = make_puffs(static_cast<int>(state.range(0)), state.range(1) != 0);
  PathSpectra<3> ps;
  prepare_path_spectra(ps, p.scene, 0.0);
  const std::vector<Vec3> points = lookup_points(p.side, int(state.range(2)));
  MediumPoint<3> m;
  size_t i = 0, present = 0;
  for (auto _ : state) {
    medium_at(p.scene, ps.media, points[i++ % points.size()], -1, m);
    present += m.mu_s.max() > 0 ? 1 : 0;
    benchmark::DoNotOptimize(m);
  }
  size_t media = 0, listed = 0;
  for (const Vec3& x : points) {
    for_each_medium_at(p.scene, x, -1, [&](int, double, double, int) { ++media; });
    listed += members_at(p.scene.field_grid, x).size();
  }
  state.counters["lookups/s"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["present"] = double(media) / double(points.size());
  state.counters["listed"] = double(listed) / double(points.size());
  benchmark::DoNotOptimize(present);
}

// Arguments: puffs, density (0 constant, 1 cloud), points (0 random, 1 along rays, 2 along rays
// in a small cube).
BENCHMARK(Lookup)->ArgsProduct({{4, 64, 1024, 10000}, {0, 1}, {0, 1, 2}});

// This machine's latency of a load whose address comes from the last load, in a working set of
// state.range(0) KiB visited in random order: the floor under a lookup whose cell list and
// objects are not in cache, for it takes three such loads, one after the other, to reach an
// object from a point (the cell's offset, its list, the object's record).
void DependentLoad(benchmark::State& state) {
  const std::size_t lines = std::size_t(state.range(0)) * 1024 / 64;
  std::vector<std::size_t> order(lines);
  for (std::size_t i = 0; i < lines; ++i) order[i] = i;
  Rng rng(3);
  for (std::size_t i = lines - 1; i > 0; --i)
    std::swap(order[i], order[std::size_t(rng.uniform() * double(i + 1)) % (i + 1)]);
  std::vector<std::size_t> next(lines * 8);  // one entry per 64-byte line
  for (std::size_t i = 0; i < lines; ++i) next[order[i] * 8] = order[(i + 1) % lines] * 8;
  std::size_t at = 0;
  for (auto _ : state) {
    at = next[at];
    benchmark::DoNotOptimize(at);
  }
}
BENCHMARK(DependentLoad)->RangeMultiplier(4)->Range(16, 1 << 17);

}  // namespace
}  // namespace nimbus

BENCHMARK_MAIN();
