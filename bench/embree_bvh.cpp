// Embree 3 against nimbus's own bounding volume hierarchy for first-hit ray queries over N objects
// (issue 26 item 1). The same N objects (spheres, or free forms of four perturbations as in
// tools/bench_scale.py objects --freeform, on a jittered 3D grid in [-1, 1]^3) are indexed by
// build_surface_index (binned SAH, render/surface_index.cpp) and by an Embree scene of one user
// geometry of N primitives (its SAH builder and SIMD traversal; each object's box rounded outward
// to floats, then grown by --pad times the scene's size against the float ray's round-off). The
// exact double-precision root finding (frep first_hit) stays in Embree's intersect callback,
// which keeps the nearest double t itself and breaks ties by object index, as `intersect` does.
// For each N it reports the build time (median), the index's memory (nimbus: its vectors' bytes;
// Embree: its memory monitor's count after the commit), and single-threaded rays/s over the same
// R random rays (median of interleaved repetitions), and checks that both find the same object
// at the same t, bit for bit, for every ray.
//
// Build: cmake -DNIMBUS_BUILD_BENCH=ON build && cmake --build build --target embree_bvh
// Usage: build/embree_bvh [--rays R] [--reps K] [--shapes spheres|freeforms|both]
//        [--freeform-max N] [--pad X] [--embree-threads T] [--quality low|medium|high]
//        [--embree-config STR] [N ...]
// Defaults: 10^5 rays, 3 repetitions, both shapes (free forms up to N = 10^5), pad 1e-6, one
// Embree build thread, quality medium, N = 100, 1000, 10000, 100000, 1000000.

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "nimbus/frep/intersect.h"
#include "nimbus/frep/primitives.h"
#include "nimbus/frep/tape.h"
#include "nimbus/render/scene.h"
#include "nimbus/render/surface_index.h"

namespace embree_bvh {

using nimbus::Box;
using nimbus::Ray;
using nimbus::RaySlabs;
using nimbus::Scene;
using nimbus::SceneObject;
using nimbus::Vec3;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The free form of tools/bench_scale.py: a unit sphere with four spherical perturbations.
nimbus::ShapePtr rock() {
  using nimbus::make_shape;
  using nimbus::QuadricNode;
  nimbus::FreeFormNode ff;
  ff.base = make_shape(QuadricNode{nimbus::sphere({0, 0, 0}, 1)});
  const struct {
    Vec3 c;
    double w;
  } bumps[] = {
      {{0.8, 0.3, 0}, 2}, {{-0.5, 0.6, 0.4}, -3}, {{0.1, -0.7, 0.6}, 2}, {{0, 0.2, -0.9}, -2}};
  for (const auto& b : bumps)
    ff.perturbations.push_back({make_shape(QuadricNode{nimbus::sphere(b.c, 0.5)}), b.w});
  return make_shape(std::move(ff));
}

// N objects on a jittered grid of k^3 cells over [-1, 1]^3 (N cells drawn at random), each a
// copy of the unit shape scaled by r and moved to its cell's jittered centre; the shape compiles
// once and is placed per copy (compile_placed), as the scene compiler does for instances.
Scene make_scene(int n, bool freeform, std::uint64_t seed) {
  const nimbus::ShapePtr shape =
      freeform ? rock() : nimbus::make_shape(nimbus::QuadricNode{nimbus::sphere({0, 0, 0}, 1)});
  const nimbus::Tape local = nimbus::compile(*shape, nimbus::FUse::Sign);
  const int k = int(std::ceil(std::cbrt(double(n)) - 1e-9));
  const double step = 2.0 / k;
  std::vector<int> cells(size_t(k) * k * k);
  for (size_t i = 0; i < cells.size(); ++i) cells[i] = int(i);
  std::mt19937_64 rng(seed);
  std::shuffle(cells.begin(), cells.end(), rng);
  std::uniform_real_distribution<double> u(0, 1);
  // A free form reaches 1.3 from its centre: its radius is smaller so it stays in its cell.
  const double r_lo = freeform ? 0.15 : 0.2, r_hi = freeform ? 0.3 : 0.35;
  Scene scene;
  scene.objects.reserve(size_t(n));
  for (int i = 0; i < n; ++i) {
    const int c = cells[size_t(i)];
    const Vec3 centre{-1 + step * (c % k + 0.4 + 0.2 * u(rng)),
                      -1 + step * ((c / k) % k + 0.4 + 0.2 * u(rng)),
                      -1 + step * (c / (k * k) + 0.4 + 0.2 * u(rng))};
    const double r = step * (r_lo + (r_hi - r_lo) * u(rng));
    const nimbus::Mat4 placement = nimbus::Mat4::translate(centre) * nimbus::Mat4::scale({r, r, r});
    SceneObject obj;
    obj.tape = nimbus::compile_placed(*shape, placement, nimbus::FUse::Sign, local.bounds);
    obj.bounds = obj.tape.bounds.box;
    obj.surface.type = nimbus::Surface::Type::Diffuse;
    scene.objects.push_back(std::move(obj));
  }
  return scene;
}

// R rays from random points on a sphere of radius 3 about the origin (outside [-1, 1]^3) towards
// random points inside the cube; unit directions.
std::vector<Ray> make_rays(int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Ray> rays(static_cast<size_t>(count));
  for (Ray& ray : rays) {
    Vec3 w;
    do w = {u(rng), u(rng), u(rng)};
    while (nimbus::dot(w, w) > 1 || nimbus::dot(w, w) < 1e-6);
    ray.o = nimbus::normalize(w) * 3.0;
    ray.d = nimbus::normalize(Vec3{u(rng), u(rng), u(rng)} - ray.o);
  }
  return rays;
}

struct Hit {
  double t = -1;
  std::uint32_t object = kNone;
};

volatile double floor_sink = 0;  // keeps the floor's first_hit calls

size_t nimbus_bytes(const nimbus::SurfaceIndex& index) {
  return index.nodes.capacity() * sizeof(nimbus::SurfaceNode) +
         index.entries.capacity() * sizeof(std::uint32_t) +
         (index.objects.capacity() + index.lights.capacity()) * sizeof(int);
}

// ---- Embree ----

std::atomic<long long> embree_bytes{0};

bool monitor(void*, ssize_t bytes, bool) {
  embree_bytes += static_cast<long long>(bytes);
  return true;
}

struct Geometry {
  const std::vector<SceneObject>* objects = nullptr;
  double pad = 0;                   // absolute, added before the rounding to floats
  mutable std::uint64_t calls = 0;  // of the intersect callback (one thread casts)
};

// The context of one ray: Embree's first (the callback gets a pointer to it), then the double
// ray and the nearest hit so far.
struct RayContext {
  RTCIntersectContext embree;
  Ray ray;
  RaySlabs slabs;
  double best_t = kInf;
  std::uint32_t best = kNone;
};

float round_down(double x) {
  const float f = static_cast<float>(x);
  return double(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float round_up(double x) {
  const float f = static_cast<float>(x);
  return double(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

void bounds_callback(const RTCBoundsFunctionArguments* args) {
  const auto* g = static_cast<const Geometry*>(args->geometryUserPtr);
  const Box& b = (*g->objects)[args->primID].bounds;
  RTCBounds* o = args->bounds_o;
  o->lower_x = round_down(b.lo.x - g->pad);
  o->lower_y = round_down(b.lo.y - g->pad);
  o->lower_z = round_down(b.lo.z - g->pad);
  o->upper_x = round_up(b.hi.x + g->pad);
  o->upper_y = round_up(b.hi.y + g->pad);
  o->upper_z = round_up(b.hi.z + g->pad);
}

// nimbus's entry test (render/scene.cpp): the root over the object's double box's part of the
// whole ray, skipped when that part begins past the nearest hit; the nearest t, then the lowest
// index. Embree's tfar only culls its float boxes, so it stays a little above the exact best.
void intersect_callback(const RTCIntersectFunctionNArguments* args) {
  if (args->N != 1 || !args->valid[0]) return;
  auto* ctx = reinterpret_cast<RayContext*>(args->context);
  const auto* g = static_cast<const Geometry*>(args->geometryUserPtr);
  ++g->calls;
  const std::uint32_t prim = args->primID;
  const SceneObject& obj = (*g->objects)[prim];
  double t0 = 0, t1 = kInf;
  if (!nimbus::clip_ray(obj.bounds, ctx->slabs, t0, t1) || t0 > ctx->best_t) return;
  const std::optional<double> t = nimbus::first_hit(obj.tape, ctx->ray, t0, t1);
  if (!t || !(*t < ctx->best_t || (*t == ctx->best_t && prim < ctx->best))) return;
  ctx->best_t = *t;
  ctx->best = prim;
  auto* rayhit = reinterpret_cast<RTCRayHit*>(args->rayhit);
  rayhit->ray.tfar = round_up(*t * (1 + 1e-6) + 1e-6);
  rayhit->hit.geomID = args->geomID;
  rayhit->hit.primID = prim;
}

struct EmbreeIndex {
  RTCScene scene = nullptr;
  Geometry geometry;
  ~EmbreeIndex() {
    if (scene) rtcReleaseScene(scene);
  }
};

void build_embree(EmbreeIndex& index, RTCDevice device, const std::vector<SceneObject>& objects,
                  double pad, RTCBuildQuality quality) {
  index.geometry = {&objects, pad};
  index.scene = rtcNewScene(device);
  rtcSetSceneBuildQuality(index.scene, quality);
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geom, unsigned(objects.size()));
  rtcSetGeometryUserData(geom, &index.geometry);
  rtcSetGeometryBoundsFunction(geom, bounds_callback, nullptr);
  rtcSetGeometryIntersectFunction(geom, intersect_callback);
  rtcSetGeometryBuildQuality(geom, quality);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(index.scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(index.scene);
}

Hit cast_embree(RTCScene scene, const Ray& ray) {
  RayContext ctx{{}, ray, RaySlabs(ray)};
  rtcInitIntersectContext(&ctx.embree);
  RTCRayHit rh{};
  rh.ray.org_x = float(ray.o.x);
  rh.ray.org_y = float(ray.o.y);
  rh.ray.org_z = float(ray.o.z);
  rh.ray.dir_x = float(ray.d.x);
  rh.ray.dir_y = float(ray.d.y);
  rh.ray.dir_z = float(ray.d.z);
  rh.ray.tnear = 0;
  rh.ray.tfar = std::numeric_limits<float>::infinity();
  rh.ray.mask = ~0u;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene, &ctx.embree, &rh);
  return ctx.best == kNone ? Hit{} : Hit{ctx.best_t, ctx.best};
}

Hit cast_nimbus(const Scene& scene, const Ray& ray) {
  const std::optional<nimbus::SurfaceHit> hit = nimbus::intersect(scene, ray, kInf);
  return hit ? Hit{hit->t, std::uint32_t(hit->object)} : Hit{};
}

struct Options {
  int rays = 100000;
  int reps = 3;
  bool spheres = true, freeforms = true;
  int freeform_max = 100000;
  double pad = 1e-6;
  int embree_threads = 1;
  std::string embree_config;  // appended to the device's configuration (e.g. verbose=1)
  RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM;
  std::vector<int> counts;
};

void run(const Options& opt, RTCDevice device, int n, bool freeform) {
  auto start = std::chrono::steady_clock::now();
  Scene scene = make_scene(n, freeform, 1234 + std::uint64_t(n));
  const double make_s = seconds_since(start);
  const std::vector<Ray> rays = make_rays(opt.rays, 99);
  // The scene's size is 2 (the cube); the pad is relative to it.
  const double pad = 2 * opt.pad;

  std::vector<double> build_s_nimbus, build_s_embree;
  size_t bytes_nimbus = 0;
  long long bytes_embree = 0;
  EmbreeIndex embree;
  for (int rep = 0; rep < opt.reps; ++rep) {
    start = std::chrono::steady_clock::now();
    scene.surfaces = nimbus::build_surface_index(scene.objects, scene.lights);
    build_s_nimbus.push_back(seconds_since(start));
    bytes_nimbus = nimbus_bytes(scene.surfaces);
    if (embree.scene) rtcReleaseScene(embree.scene);
    embree.scene = nullptr;
    const long long before = embree_bytes;
    start = std::chrono::steady_clock::now();
    build_embree(embree, device, scene.objects, pad, opt.quality);
    build_s_embree.push_back(seconds_since(start));
    bytes_embree = embree_bytes - before;
  }

  std::vector<Hit> hits_nimbus(rays.size()), hits_embree(rays.size());
  std::vector<double> rate_nimbus, rate_embree;
  embree.geometry.calls = 0;
  for (int rep = 0; rep < opt.reps; ++rep) {
    start = std::chrono::steady_clock::now();
    for (size_t i = 0; i < rays.size(); ++i) hits_nimbus[i] = cast_nimbus(scene, rays[i]);
    rate_nimbus.push_back(double(rays.size()) / seconds_since(start));
    start = std::chrono::steady_clock::now();
    for (size_t i = 0; i < rays.size(); ++i) hits_embree[i] = cast_embree(embree.scene, rays[i]);
    rate_embree.push_back(double(rays.size()) / seconds_since(start));
  }
  // The floor under both: the double box clip and first_hit on the object hit alone, per ray.
  start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < rays.size(); ++i) {
    if (hits_nimbus[i].object == kNone) continue;
    const SceneObject& obj = scene.objects[hits_nimbus[i].object];
    double t0 = 0, t1 = kInf;
    if (nimbus::clip_ray(obj.bounds, RaySlabs(rays[i]), t0, t1))
      floor_sink = floor_sink + nimbus::first_hit(obj.tape, rays[i], t0, t1).value_or(0);
  }
  const double rate_floor = double(rays.size()) / seconds_since(start);
  size_t mismatches = 0, hit_count = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const Hit &a = hits_nimbus[i], &b = hits_embree[i];
    hit_count += a.object != kNone;
    if (a.object != b.object || std::memcmp(&a.t, &b.t, sizeof(double)) != 0) {
      if (++mismatches <= 5)
        std::fprintf(stderr, "  ray %zu: nimbus object %d t %.17g, embree object %d t %.17g\n", i,
                     int(a.object), a.t, int(b.object), b.t);
    }
  }
  const double rn = median(rate_nimbus), re = median(rate_embree);
  std::printf("| %s | %d | %.2f | %.2f | %.2f | %.2f | %.3g | %.3g | %.2f | %zu |\n",
              freeform ? "free forms" : "spheres", n, 1e3 * median(build_s_nimbus),
              1e3 * median(build_s_embree), double(bytes_nimbus) / (1 << 20),
              double(bytes_embree) / (1 << 20), rn, re, re / rn, mismatches);
  std::fprintf(stderr,
               "  (%s N %d: scene made in %.2f s, %.1f %% of rays hit; first_hit on the object "
               "hit alone: %.3g rays/s; Embree callbacks per ray %.2f)\n",
               freeform ? "free forms" : "spheres", n, make_s,
               100.0 * double(hit_count) / double(rays.size()), rate_floor,
               double(embree.geometry.calls) / double(opt.reps * rays.size()));
  std::fflush(stdout);
}

int usage() {
  std::fprintf(stderr,
               "usage: embree_bvh [--rays R] [--reps K] [--shapes spheres|freeforms|both]\n"
               "       [--freeform-max N] [--pad X] [--embree-threads T]\n"
               "       [--quality low|medium|high] [--embree-config STR] [N ...]\n");
  return 2;
}

int main(int argc, char** argv) {
  Options opt;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--rays" && has_value) {
      opt.rays = std::atoi(argv[++i]);
    } else if (a == "--reps" && has_value) {
      opt.reps = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--shapes" && has_value) {
      const std::string s = argv[++i];
      opt.spheres = s == "spheres" || s == "both";
      opt.freeforms = s == "freeforms" || s == "both";
      if (!opt.spheres && !opt.freeforms) return usage();
    } else if (a == "--freeform-max" && has_value) {
      opt.freeform_max = std::atoi(argv[++i]);
    } else if (a == "--pad" && has_value) {
      opt.pad = std::atof(argv[++i]);
    } else if (a == "--embree-threads" && has_value) {
      opt.embree_threads = std::atoi(argv[++i]);
    } else if (a == "--embree-config" && has_value) {
      opt.embree_config = argv[++i];
    } else if (a == "--quality" && has_value) {
      const std::string q = argv[++i];
      if (q == "low") {
        opt.quality = RTC_BUILD_QUALITY_LOW;
      } else if (q == "medium") {
        opt.quality = RTC_BUILD_QUALITY_MEDIUM;
      } else if (q == "high") {
        opt.quality = RTC_BUILD_QUALITY_HIGH;
      } else {
        return usage();
      }
    } else if (!a.empty() && a[0] != '-' && std::atoi(a.c_str()) > 0) {
      opt.counts.push_back(std::atoi(a.c_str()));
    } else {
      return usage();
    }
  }
  if (opt.counts.empty()) opt.counts = {100, 1000, 10000, 100000, 1000000};
  std::string config = "threads=" + std::to_string(opt.embree_threads);
  if (!opt.embree_config.empty()) config += "," + opt.embree_config;
  RTCDevice device = rtcNewDevice(config.c_str());
  if (!device) {
    std::fprintf(stderr, "embree_bvh: rtcNewDevice failed (%d)\n", int(rtcGetDeviceError(nullptr)));
    return 1;
  }
  rtcSetDeviceMemoryMonitorFunction(device, monitor, nullptr);
  std::printf("%d rays, median of %d, one thread casting; Embree %d build thread(s), pad %g\n\n",
              opt.rays, opt.reps, opt.embree_threads, opt.pad);
  std::printf(
      "| shape | N | build ms nimbus | build ms embree | MiB nimbus | MiB embree | rays/s nimbus "
      "| rays/s embree | embree/nimbus | mismatches "
      "|\n|---|---|---|---|---|---|---|---|---|---|\n");
  for (const bool freeform : {false, true}) {
    if (freeform ? !opt.freeforms : !opt.spheres) continue;
    for (const int n : opt.counts)
      if (!freeform || n <= opt.freeform_max) run(opt, device, n, freeform);
  }
  rtcReleaseDevice(device);
  return 0;
}

}  // namespace embree_bvh

int main(int argc, char** argv) {
  return embree_bvh::main(argc, argv);
}
