#include "nimbus/io/vdb_export.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

#include "nimbus/io/atomic_file.h"
#include "nimbus/media/vdb_module.h"
#include "nimbus/os/shared_module.h"

// The grid is built here as plain leaves (media/vdb_module.h); nimbus_openvdb.so, loaded before
// the build starts, makes them an OpenVDB grid and writes it.

namespace nimbus {
namespace {

using Leaf = VdbExportLeaf;
constexpr int kLeafDim = 8;

// The voxel centres i H inside [lo, hi] on one axis.
struct AxisRange {
  long long first, last;
};

// Saturated at 2^62 in magnitude, so that the cast is defined for any quotient (issue 29: a
// voxel size of 1e-300 overflowed it); indices past 2^30 are refused below.
long long to_index(double x) {
  return static_cast<long long>(std::clamp(x, -0x1p62, 0x1p62));
}

AxisRange axis_range(double lo, double hi, double h) {
  return {to_index(std::ceil(lo / h)), to_index(std::floor(hi / h))};
}

long long floor_div(long long a, long long b) {
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}

std::array<float, 3> to_floats(const Rgb& c) {
  return {float(c[0]), float(c[1]), float(c[2])};
}

bool is_active(const Leaf& leaf, int i) {
  return leaf.active[i / 64] >> (i % 64) & 1;
}

}  // namespace

int vdb_export_object(const SceneDesc& desc, int requested) {
  const int n = static_cast<int>(desc.objects.size());
  if (requested < 0) {
    for (int i = 0; i < n; ++i)
      if (desc.objects[i].medium >= 0) return i;
    throw std::invalid_argument(
        fmt::format("{}: no object holds a medium: there is nothing to export", desc.source));
  }
  if (requested >= n)
    throw std::invalid_argument(fmt::format("--object {}: {} has {} object{} (0 to {})", requested,
                                            desc.source, n, n == 1 ? "" : "s", n - 1));
  if (desc.objects[requested].medium < 0)
    throw std::invalid_argument(fmt::format("--object {}: {}: {} holds no medium", requested,
                                            desc.source, desc.objects[requested].json_path));
  if (desc.objects[requested].instances)
    throw std::invalid_argument(
        fmt::format("--object {}: {}: {} has instances; export one object (without \"instances\")",
                    requested, desc.source, desc.objects[requested].json_path));
  return requested;
}

int vdb_export_compiled(const Scene& scene, int object) {
  for (std::size_t i = 0; i < scene.objects.size(); ++i)
    if (scene.objects[i].source == object) return int(i);
  throw std::invalid_argument(
      fmt::format("--object {}: the object holds nothing (its shape is empty)", object));
}

std::string vdb_voxel_size_problem(double h) {
  if (h >= kVdbExportMinVoxelSize && h <= kVdbExportMaxVoxelSize) return {};
  return fmt::format("must be in [{:g}, {:g}], not {:g}", kVdbExportMinVoxelSize,
                     kVdbExportMaxVoxelSize, h);
}

double vdb_export_voxels(const Scene& scene, int object, double h) {
  const Box& b = scene.objects.at(object).bounds;
  // In doubles: the quotients may be far past any integer type.
  double count = 1;
  for (int k = 0; k < 3; ++k) {
    const double n = std::floor(b.hi[k] / h) - std::ceil(b.lo[k] / h) + 1;
    count *= std::isnan(n) ? std::numeric_limits<double>::infinity() : std::max(0.0, n);
  }
  return count;
}

VdbExportResult export_vdb(const Scene& scene, int object, double h, const std::string& path,
                           const BuildMonitor& monitor) {
  if (const std::string problem = vdb_voxel_size_problem(h); !problem.empty())
    throw std::invalid_argument("--voxel-size: " + problem);
  const SceneObject& obj = scene.objects.at(object);
  if (obj.medium < 0) throw std::invalid_argument(fmt::format("object {} holds no medium", object));
  const Medium& medium = scene.media[obj.medium];
  // One density grid with constant coefficients beside it cannot hold coefficients that vary
  // apart from the density.
  if (medium.sigma_a_texture || medium.sigma_s_texture)
    throw std::invalid_argument(fmt::format(
        "object {}: its medium's sigma_a or sigma_s is textured; an export holds one density grid "
        "and constant coefficients",
        object));
  const double voxels = vdb_export_voxels(scene, object, h);
  if (!(voxels <= kVdbExportMaxVoxels))
    throw std::invalid_argument(fmt::format(
        "--voxel-size {}: the object's bounds hold {:.3g} voxels, more than the {:.3g} an export "
        "may have; use a larger voxel size",
        h, voxels, kVdbExportMaxVoxels));
  // A multiple of H lies in any interval at least H long.
  if (voxels < 1) {
    const Vec3 extent = obj.bounds.hi - obj.bounds.lo;
    throw std::invalid_argument(fmt::format(
        "--voxel-size {}: no voxel centre (i H, j H, k H) lies in the object's bounds; use a "
        "voxel size of at most {:.3g}, the bounds' smallest extent",
        h, std::min({extent.x, extent.y, extent.z})));
  }

  // Before the grid's build, which may take minutes: a module that cannot be loaded is one line.
  const VdbModule* module = nullptr;
  try {
    module = &vdb_module();
  } catch (const ModuleLoadError& e) {
    throw std::invalid_argument(
        fmt::format("writing VDB files needs nimbus's OpenVDB module: {}", e.what()));
  }

  // Blocks of 8³ voxels, aligned as OpenVDB's leaves, over the voxel centres in the bounds.
  AxisRange voxel[3], block[3];
  long long blocks_along[3];
  for (int k = 0; k < 3; ++k) {
    voxel[k] = axis_range(obj.bounds.lo[k], obj.bounds.hi[k], h);
    if (std::max(std::abs(voxel[k].first), std::abs(voxel[k].last)) > (1LL << 30))
      throw std::invalid_argument(fmt::format(
          "--voxel-size {}: voxel indices beyond 2^30 (the object is far from the origin); use "
          "a larger voxel size",
          h));
    block[k] = {floor_div(voxel[k].first, kLeafDim), floor_div(voxel[k].last, kLeafDim)};
    blocks_along[k] = std::max(0LL, block[k].last - block[k].first + 1);
  }
  const std::size_t blocks =
      voxels > 0 ? std::size_t(blocks_along[0] * blocks_along[1] * blocks_along[2]) : 0;

  BuildWatch progress(monitor);
  std::vector<std::unique_ptr<Leaf>> leaves(blocks);
  std::atomic<std::size_t> done{0};
  const Density& density = *medium.density;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks), [&](const auto& range) {
    for (std::size_t b = range.begin(); b != range.end(); ++b) {
      if (progress.cancelled()) return;
      const long long bx =
          block[0].first + static_cast<long long>(b) / (blocks_along[1] * blocks_along[2]);
      const long long by =
          block[1].first + static_cast<long long>(b) / blocks_along[2] % blocks_along[1];
      const long long bz = block[2].first + static_cast<long long>(b) % blocks_along[2];
      const long long origin[3] = {bx * kLeafDim, by * kLeafDim, bz * kLeafDim};
      long long lo[3], hi[3];
      Box box;
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::max(origin[k], voxel[k].first);
        hi[k] = std::min(origin[k] + kLeafDim - 1, voxel[k].last);
        box.lo[k] = double(lo[k]) * h;
        box.hi[k] = double(hi[k]) * h;
      }
      progress.report(double(++done) / double(blocks));
      // A block where the object's function or the density's range rules the medium out costs
      // no lookup: sparse media export in time proportional to their volume.
      const Interval F = evaluate(obj.tape, box);
      if (!(F.hi > 0) || !(density.range(box, F).hi > 0)) continue;
      auto leaf = std::make_unique<Leaf>();
      leaf->origin = {int(origin[0]), int(origin[1]), int(origin[2])};
      bool any = false;
      for (long long i = lo[0]; i <= hi[0]; ++i)
        for (long long j = lo[1]; j <= hi[1]; ++j)
          for (long long k = lo[2]; k <= hi[2]; ++k) {
            const Vec3 x{double(i) * h, double(j) * h, double(k) * h};
            const double f = evaluate(obj.tape, x);
            if (!(f > 0)) continue;  // outside the object there is no medium
            const double d = medium.scale * density.value(x, f);
            if (!(d > 0)) continue;
            const int at = int((i - origin[0]) * 64 + (j - origin[1]) * 8 + (k - origin[2]));
            leaf->values[at] = static_cast<float>(d);
            leaf->active[at / 64] |= std::uint64_t(1) << (at % 64);
            any = true;
          }
      if (any) leaves[b] = std::move(leaf);
    }
  });
  VdbExportResult result;
  if (progress.cancelled()) {
    result.cancelled = true;
    return result;
  }
  progress.report(1);

  for (const auto& leaf : leaves)
    if (leaf)
      for (int i = 0; i < 512; ++i)
        if (is_active(*leaf, i))
          result.max_density = std::max(result.max_density, double(leaf->values[i]));
  if (!(result.max_density <= std::numeric_limits<float>::max()))
    throw std::invalid_argument(fmt::format(
        "the density reaches {}, beyond the float range of a VDB grid", result.max_density));
  // Below the threshold voxels go inactive (and 0), and leaves left without active voxels go.
  const float threshold = static_cast<float>(kVdbExportThreshold * result.max_density);
  std::vector<Leaf> kept;
  for (auto& leaf : leaves) {
    if (!leaf) continue;
    bool any = false;
    for (int i = 0; i < 512; ++i) {
      if (!is_active(*leaf, i)) continue;
      if (leaf->values[i] < threshold) {
        leaf->values[i] = 0.0f;
        leaf->active[i / 64] &= ~(std::uint64_t(1) << (i % 64));
      } else {
        ++result.active_voxels;
        any = true;
      }
    }
    if (any) kept.push_back(*leaf);
    leaf.reset();
  }
  // An empty grid would be a file that holds nothing: the voxels missed the medium.
  if (result.active_voxels == 0)
    throw std::invalid_argument(fmt::format(
        "--voxel-size {}: none of the {:.0f} voxel centres in the object's bounds has medium; use "
        "a smaller voxel size",
        h, voxels));

  VdbWriteRequest request;
  request.leaves = &kept;
  request.voxel_size = h;
  request.sigma_a = to_floats(medium.sigma_a.rgb);
  request.sigma_s = to_floats(medium.sigma_s.rgb);
  request.phase_g = float(medium.g);
  request.creator = "nimbus " NIMBUS_VERSION;
  write_atomically(path, [&](const std::string& temp) {
    request.path = temp;
    if (const std::string problem = module->write(request); !problem.empty())
      throw std::runtime_error(problem);
  });
  return result;
}

}  // namespace nimbus
