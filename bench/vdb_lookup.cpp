// Trilinear lookups in a VDB grid per second (issue 14): OpenVDB's BoxSampler through a value
// accessor against NanoVDB's trilinear stencil through its read accessor, on the same sparse
// cloud, and the "vdb" density's value() that nimbus renders with. A density lookup cannot keep
// an accessor between calls (value() is const and called from every thread), so each library is
// measured with a fresh accessor per lookup, the way nimbus would use it, and with one kept
// across lookups, the best case. Points are either random in the grid's bounding box
// (incoherent) or steps of half a voxel along random rays (what tracking asks).
// Run: build/vdb_lookup --benchmark_repetitions=3 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>
#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <nanovdb/util/SampleFromVoxels.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>

#include <cmath>
#include <filesystem>
#include <vector>

#include "nimbus/math/rng.h"
#include "nimbus/media/vdb_density.h"

namespace nimbus {
namespace {

constexpr int kRadius = 48;  // voxels: the cloud fills a ball of this radius, the rest is empty
constexpr int kPoints = 1 << 16;

// A ball of density falling off towards its edge, modulated by a deterministic ripple, inside a
// bounding box twice its size: leaves, partly filled leaves and empty tiles.
openvdb::FloatGrid::Ptr make_cloud() {
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
  auto acc = grid->getAccessor();
  for (int i = -kRadius; i <= kRadius; ++i)
    for (int j = -kRadius; j <= kRadius; ++j)
      for (int k = -kRadius; k <= kRadius; ++k) {
        const double r = std::sqrt(double(i * i + j * j + k * k)) / kRadius;
        if (r >= 1) continue;
        const double ripple = 0.75 + 0.25 * std::sin(0.3 * i) * std::cos(0.2 * j + 0.1 * k);
        acc.setValue({i, j, k}, float((1 - r * r) * ripple));
      }
  grid->setTransform(openvdb::math::Transform::createLinearTransform(0.02));
  grid->setName("density");
  grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  return grid;
}

// Index-space points in the cloud's bounding box [-R, R]³ (about half of them inside the ball),
// random or along random rays in half-voxel steps.
std::vector<openvdb::Vec3d> make_points(bool along_rays) {
  Rng rng(11);
  std::vector<openvdb::Vec3d> p;
  const double extent = kRadius;
  while (int(p.size()) < kPoints) {
    openvdb::Vec3d o(extent * (2 * rng.uniform() - 1), extent * (2 * rng.uniform() - 1),
                     extent * (2 * rng.uniform() - 1));
    if (!along_rays) {
      p.push_back(o);
      continue;
    }
    openvdb::Vec3d d(2 * rng.uniform() - 1, 2 * rng.uniform() - 1, 2 * rng.uniform() - 1);
    d.normalize();
    for (int s = 0; s < 256 && int(p.size()) < kPoints; ++s) {
      const openvdb::Vec3d q = o + d * (0.5 * s);
      if (std::abs(q[0]) > extent || std::abs(q[1]) > extent || std::abs(q[2]) > extent) break;
      p.push_back(q);
    }
  }
  return p;
}

struct Fixture {
  openvdb::FloatGrid::Ptr open;
  nanovdb::GridHandle<nanovdb::HostBuffer> handle;
  const nanovdb::NanoGrid<float>* nano = nullptr;
  std::vector<openvdb::Vec3d> random, rays;

  static const Fixture& get() {
    static const Fixture f = [] {
      openvdb::initialize();
      Fixture x;
      x.open = make_cloud();
      x.handle = nanovdb::openToNanoVDB(*x.open);
      x.nano = x.handle.grid<float>();
      x.random = make_points(false);
      x.rays = make_points(true);
      return x;
    }();
    return f;
  }
  const std::vector<openvdb::Vec3d>& points(const benchmark::State& state) const {
    return state.range(0) ? rays : random;
  }
};

void label(benchmark::State& state) {
  state.SetLabel(state.range(0) ? "along rays" : "random points");
  state.SetItemsProcessed(state.iterations() * kPoints);
}

void BM_OpenVdbBoxSamplerFreshAccessor(benchmark::State& state) {
  const Fixture& f = Fixture::get();
  const openvdb::FloatGrid& grid = *f.open;
  for (auto _ : state) {
    float sum = 0;
    for (const openvdb::Vec3d& p : f.points(state)) {
      const auto acc = grid.getConstUnsafeAccessor();
      sum += openvdb::tools::BoxSampler::sample(acc, p);
    }
    benchmark::DoNotOptimize(sum);
  }
  label(state);
}

void BM_OpenVdbBoxSamplerKeptAccessor(benchmark::State& state) {
  const Fixture& f = Fixture::get();
  const auto acc = f.open->getConstUnsafeAccessor();
  for (auto _ : state) {
    float sum = 0;
    for (const openvdb::Vec3d& p : f.points(state))
      sum += openvdb::tools::BoxSampler::sample(acc, p);
    benchmark::DoNotOptimize(sum);
  }
  label(state);
}

void BM_NanoVdbTrilinearFreshAccessor(benchmark::State& state) {
  const Fixture& f = Fixture::get();
  for (auto _ : state) {
    float sum = 0;
    for (const openvdb::Vec3d& p : f.points(state)) {
      const auto acc = f.nano->getAccessor();
      const nanovdb::SampleFromVoxels<decltype(acc), 1, false> sampler(acc);
      sum += sampler(nanovdb::Vec3d(p[0], p[1], p[2]));
    }
    benchmark::DoNotOptimize(sum);
  }
  label(state);
}

void BM_NanoVdbTrilinearKeptAccessor(benchmark::State& state) {
  const Fixture& f = Fixture::get();
  const auto acc = f.nano->getAccessor();
  const nanovdb::SampleFromVoxels<decltype(acc), 1, false> sampler(acc);
  for (auto _ : state) {
    float sum = 0;
    for (const openvdb::Vec3d& p : f.points(state))
      sum += sampler(nanovdb::Vec3d(p[0], p[1], p[2]));
    benchmark::DoNotOptimize(sum);
  }
  label(state);
}

// nimbus's "vdb" density (media/vdb_density.h) read from the same grid written to a file: world
// points, its own trilinear interpolation in double.
void BM_NimbusVdbDensityValue(benchmark::State& state) {
  const Fixture& f = Fixture::get();
  static const DensityPtr density = [&] {
    const std::filesystem::path file =
        std::filesystem::temp_directory_path() / "nimbus_bench_vdb_lookup.vdb";
    openvdb::io::File(file.string()).write({f.open});
    VdbParams params;
    params.file = file.string();
    DensityPtr d = make_vdb_density(params);
    std::filesystem::remove(file);
    return d;
  }();
  std::vector<Vec3> world;
  for (const openvdb::Vec3d& p : f.points(state)) {
    const openvdb::Vec3d w = f.open->indexToWorld(p);
    world.push_back({w[0], w[1], w[2]});
  }
  for (auto _ : state) {
    double sum = 0;
    for (const Vec3& x : world) sum += density->value(x, 1.0);
    benchmark::DoNotOptimize(sum);
  }
  label(state);
}

BENCHMARK(BM_OpenVdbBoxSamplerFreshAccessor)->Arg(0)->Arg(1);
BENCHMARK(BM_OpenVdbBoxSamplerKeptAccessor)->Arg(0)->Arg(1);
BENCHMARK(BM_NanoVdbTrilinearFreshAccessor)->Arg(0)->Arg(1);
BENCHMARK(BM_NanoVdbTrilinearKeptAccessor)->Arg(0)->Arg(1);
BENCHMARK(BM_NimbusVdbDensityValue)->Arg(0)->Arg(1);

}  // namespace
}  // namespace nimbus

BENCHMARK_MAIN();
