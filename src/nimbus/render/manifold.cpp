#include "nimbus/render/manifold.h"

#include <algorithm>
#include <cmath>

#include "nimbus/frep/tape_eval.h"
#include "nimbus/math/box.h"
#include "nimbus/math/constants.h"
#include "nimbus/render/material.h"

namespace nimbus {
namespace {

// Newton's method: at most kMaxSteps iterations, each step at most kMaxStep (radians in the
// tangent plane of the first direction) and halved at most kMaxHalvings times while the miss
// does not shrink. Derivatives by forward differences of step kDiff: the boundaries are exact to
// double precision, so the difference quotients are good to about 1e-8.
constexpr int kMaxSteps = 16;
constexpr int kMaxHalvings = 8;
constexpr double kMaxStep = 1.0;
constexpr double kDiff = 1e-7;
// How far (relative) a vertex may move from the nearby chain's when it is sought by Newton's
// method (hit_near): across a difference quotient's step, and across a step of the walk.
constexpr double kNearDiff = 1e-4;
constexpr double kNearStep = 0.25;
// A chain of one refraction starts Newton's method after this many fixed-point steps (seed).
constexpr int kSeedSteps = 3;
// The walk has converged when the half vector's tangential part is below this.
constexpr double kTolerance = 1e-10;

// The chain followed from the start along one first direction.
struct Traced {
  Vec3 x[kMaxChainVertices], n[kMaxChainVertices];
  Vec3 d;  // the direction leaving the last vertex followed (refracted or not)
  double transmission = 1;
};

// Follows direction w from the start to the solid's boundary `vertices` times (in, then out; or
// only out from inside), refracting by Snell's law at the exact normal at the first `refract` of
// them. None where the ray misses the boundary, meets it from the wrong side, the normal is
// undefined (∇F = 0) or refraction is total internal reflection.
// With `near`, a chain traced along a nearby direction, each vertex is first sought by Newton's
// method along the ray from near's, within `reach` (relative) of it: the walk's neighbouring
// directions then cost a few evaluations of F, not a root isolation. Where that fails, or for a
// non-convex boundary finds a crossing other than the first, the chain's shadow segments are
// blocked and it brings no light; the walk stays deterministic, which is all MIS's
// weights ask.
std::optional<double> hit_near(const Tape& tape, const Ray& ray, const Vec3& near, double reach) {
  const double t0 = dot(near - ray.o, ray.d);
  double t = t0;
  for (int i = 0; i < 8; ++i) {
    const DualGrad f = value_gradient(tape, ray.at(t));
    const double slope = dot(f.grad, ray.d);
    if (!(slope != 0) || !std::isfinite(slope)) return std::nullopt;
    const double step = f.value / slope;
    t -= step;
    if (!(std::abs(t - t0) <= reach * (1 + std::abs(t0))) || !(t > 0)) return std::nullopt;
    if (std::abs(step) <= 1e-15 * (1 + std::abs(t))) return t;
  }
  return std::nullopt;
}

std::optional<Traced> trace(const Scene& scene, const ChainStart& start, const ChainShape& shape,
                            const Vec3& w, int refract, const Traced* near = nullptr,
                            double reach = 0) {
  if (start.on_surface && !(dot(w, start.n) > 0)) return std::nullopt;
  const SceneObject& obj = scene.objects[size_t(shape.solid)];
  const double ior = obj.surface.ior;
  Traced out;
  Vec3 o = start.on_surface ? offset_origin(scene, start.p, start.n, w) : start.p;
  Vec3 d = w;
  for (int v = 0; v < shape.vertices; ++v) {
    const Ray ray{o, d};
    std::optional<double> t;
    if (near) t = hit_near(obj.tape, ray, near->x[v], reach);
    if (!t) {
      double t0 = 0, t1 = kInf;
      if (!clip_ray(obj.bounds, ray, t0, t1)) return std::nullopt;
      t = first_hit(obj.tape, ray, t0, t1);
      if (!t) return std::nullopt;
    }
    const Vec3 x = ray.at(*t);
    const Vec3 g = gradient(obj.tape, x);
    const double g_len = length(g);
    if (!(g_len > 0) || !std::isfinite(g_len)) return std::nullopt;
    const Vec3 n = -g / g_len;  // outward
    const double cos_d = dot(d, n);
    const bool entering = cos_d < 0;
    // Two refractions go in then out; one goes out.
    if (entering != (shape.vertices == 2 && v == 0)) return std::nullopt;
    out.x[v] = x;
    out.n[v] = n;
    if (v == refract) break;
    const double cos_i = std::abs(cos_d);
    const Vec3 nf = entering ? n : -n;  // on the side the ray comes from
    const double eta = entering ? ior : 1 / ior;
    const double sin2_t = (1 - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1) return std::nullopt;
    const double cos_t = std::sqrt(1 - sin2_t);
    d = normalize(d / eta + nf * (cos_i / eta - cos_t));  // Snell's law
    out.transmission *= 1 - fresnel_dielectric(cos_i, eta);
    o = offset_origin(scene, x, n, d);
  }
  out.d = d;
  return out;
}

// The direction from the chain's last vertex to the target.
Vec3 towards_target(const Traced& c, int vertices, const ChainTarget& target) {
  return target.at_infinity ? target.direction : normalize(target.point - c.x[vertices - 1]);
}

// The constraint of the chain's last vertex (Hanika et al. 2015, eq. 2): refraction from the
// arriving direction to the target's is where the generalized half vector η_i ω_i + η_o ω_o is
// normal to the boundary; its tangential part, for a chain traced up to that vertex. Defined
// whatever the angles, so the walk may cross directions that total internal reflection forbids.
Vec3 half_vector_miss(const Traced& c, int vertices, const ChainTarget& target, double ior) {
  const Vec3& n = c.n[vertices - 1];
  const Vec3 w_i = -c.d, w_o = towards_target(c, vertices, target);
  const bool from_inside = dot(w_i, n) < 0;
  const Vec3 h = normalize(w_i * (from_inside ? ior : 1.0) + w_o * (from_inside ? 1.0 : ior));
  return h - n * dot(h, n);
}

// The miss of a fully refracted chain: for a target at infinity, d_out − ω_target (radians, to
// first order); for a target point y, y's offset across the line leaving the last refraction.
// Its derivative in the first direction gives the generalized geometry term.
Vec3 forward_miss(const Traced& c, int vertices, const ChainTarget& target) {
  if (target.at_infinity) return c.d - target.direction;
  const Vec3 v = target.point - c.x[vertices - 1];
  return v - c.d * dot(v, c.d);
}

struct Frame {
  Vec3 s, t;
  double u(const Vec3& e) const { return dot(e, s); }
  double v(const Vec3& e) const { return dot(e, t); }
};

Frame frame_across(const Vec3& n) {
  Frame f;
  orthonormal_basis(n, f.s, f.t);
  return f;
}

// The 2 x 2 derivative of miss(trace(w)) in w's tangent frame, whose components are taken in
// `across`, by forward differences from the value e0 at w; false where a neighbour fails.
template <class Miss>
bool derivative(const Scene& scene, const ChainStart& start, const ChainShape& shape, const Vec3& w,
                const Traced& at, const Frame& tangent, const Frame& across, const Vec3& e0,
                int refract, Miss&& miss, double J[2][2]) {
  for (int j = 0; j < 2; ++j) {
    const Vec3 wj = normalize(w + (j == 0 ? tangent.s : tangent.t) * kDiff);
    const auto tj = trace(scene, start, shape, wj, refract, &at, kNearDiff);
    if (!tj) return false;
    const Vec3 ej = miss(*tj);
    J[0][j] = (across.u(ej) - across.u(e0)) / kDiff;
    J[1][j] = (across.v(ej) - across.v(e0)) / kDiff;
  }
  return true;
}

}  // namespace

bool has_dielectric_solid(const Scene& scene) {
  return std::any_of(scene.objects.begin(), scene.objects.end(), [](const SceneObject& o) {
    return smooth_dielectric(o.surface);
  });
}

std::optional<ChainShape> chain_shape(const Scene& scene, const ChainStart& start,
                                      const ChainTarget& target) {
  Vec3 d = target.at_infinity ? target.direction : target.point - start.p;
  double dist = kInf;
  if (!target.at_infinity) {
    dist = length(d);
    if (!(dist > 0)) return std::nullopt;
    d = d / dist;
  }
  const Vec3 o = start.on_surface ? offset_origin(scene, start.p, start.n, d) : start.p;
  const auto hit = intersect(scene, {o, d}, dist * (1 - 1e-7));
  if (!hit || hit->object < 0) return std::nullopt;
  if (start.inside >= 0)
    return hit->object == start.inside ? std::optional<ChainShape>({start.inside, 1, hit->t})
                                       : std::nullopt;
  if (!smooth_dielectric(scene.objects[size_t(hit->object)].surface)) return std::nullopt;
  return ChainShape{hit->object, 2, hit->t};
}

// One fixed-point step for a chain of one refraction traced to its exit: the direction along
// which light from the target, refracted inwards at that exit, would arrive. At a sphere's
// centre each step divides the error by η / (η − 1) (3 for glass); near the boundary, where the
// exit hardly moves, one step nearly solves it. None where the target is behind the boundary.
std::optional<Vec3> fixed_point_step(const Traced& c, const ChainTarget& target, double ior) {
  const Vec3 n = c.n[0], w_o = towards_target(c, 1, target);
  const double cos_o = dot(w_o, n);
  if (!(cos_o > 0)) return std::nullopt;
  // −w_o refracted into the solid (Snell's law from outside), reversed.
  const double sin2_t = (1 - cos_o * cos_o) / (ior * ior);
  return normalize(w_o / ior + n * (std::sqrt(1 - sin2_t) - cos_o / ior));
}

ChainSeed seed_chain(const Scene& scene, const ChainStart& start, const ChainTarget& target,
                     const ChainShape& shape) {
  const Vec3 w = target.at_infinity ? target.direction : normalize(target.point - start.p);
  const SceneObject& obj = scene.objects[size_t(shape.solid)];
  Traced straight;
  straight.x[0] = start.p + w * shape.t_boundary;
  if (shape.vertices != 1) {
    // Through the solid: the straight ray's chord, whose medium the walk probability reads.
    const Ray ray{offset_origin(scene, straight.x[0], -w, w), w};
    double t0 = 0, t1 = kInf;
    const auto t =
        clip_ray(obj.bounds, ray, t0, t1) ? first_hit(obj.tape, ray, t0, t1) : std::nullopt;
    return {w, straight.x[0], shape.t_boundary, t ? *t : 0.0};
  }
  // One fixed-point step from the straight ray's exit (solve_chain takes more).
  const auto exit = trace(scene, start, shape, w, 0, &straight, kNearStep);
  const auto w1 = exit ? fixed_point_step(*exit, target, obj.surface.ior) : std::nullopt;
  if (!w1) return {w, straight.x[0], shape.t_boundary, 0.0};
  const auto c = trace(scene, start, shape, *w1, 0, &*exit, kNearStep);
  if (!c) return {w, straight.x[0], shape.t_boundary, 0.0};
  return {*w1, c->x[0], length(c->x[0] - start.p), 0.0};
}

std::optional<SpecularChain> solve_chain(const Scene& scene, const ChainStart& start,
                                         const ChainTarget& target, const ChainShape& shape,
                                         const ChainSeed& seed, ManifoldCounters& counters) {
  ++counters.walks;
  const int k = shape.vertices;
  const double ior = scene.objects[size_t(shape.solid)].surface.ior;
  const int last = k - 1;  // the vertex whose refraction the walk solves for
  auto miss = [&](const Traced& c) { return half_vector_miss(c, k, target, ior); };
  Vec3 w = seed.w;
  Traced at_seed;
  at_seed.x[0] = seed.x_first;
  auto traced = trace(scene, start, shape, w, last, &at_seed, kNearStep);
  if (!traced) return std::nullopt;
  // More fixed-point steps for one refraction, then Newton's method.
  for (int i = 1; k == 1 && i < kSeedSteps; ++i) {
    const auto w_next = fixed_point_step(*traced, target, ior);
    if (!w_next) break;
    auto t_next = trace(scene, start, shape, *w_next, last, &*traced, kNearStep);
    if (!t_next) break;
    w = *w_next;
    traced = t_next;
  }
  Vec3 e = miss(*traced);

  for (int step = 0;; ++step) {
    if (length(e) <= kTolerance) break;
    if (step == kMaxSteps) return std::nullopt;
    ++counters.newton_steps;
    const Frame tangent = frame_across(w), across = frame_across(traced->n[last]);
    double J[2][2];
    if (!derivative(scene, start, shape, w, *traced, tangent, across, e, last, miss, J))
      return std::nullopt;
    const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    if (!std::isfinite(det) || det == 0) return std::nullopt;
    // Newton's step solves J Δ = −e, shortened while the miss grows.
    const double eu = across.u(e), ev = across.v(e);
    double da = -(J[1][1] * eu - J[0][1] * ev) / det;
    double db = -(-J[1][0] * eu + J[0][0] * ev) / det;
    const double len = std::hypot(da, db);
    if (len > kMaxStep) {
      da *= kMaxStep / len;
      db *= kMaxStep / len;
    }
    bool moved = false;
    for (int h = 0; h <= kMaxHalvings && !moved; ++h, da *= 0.5, db *= 0.5) {
      const Vec3 w_next = normalize(w + tangent.s * da + tangent.t * db);
      const auto t_next = trace(scene, start, shape, w_next, last, &*traced, kNearStep);
      if (!t_next) continue;
      const Vec3 e_next = miss(*t_next);
      if (!(length(e_next) < length(e))) continue;
      w = w_next;
      traced = t_next;
      e = e_next;
      moved = true;
    }
    if (!moved) return std::nullopt;
  }

  // The solution refracts at every vertex (the half vector also vanishes where both directions
  // lie on one side), and its generalized geometry term is that of the refracted chain.
  const auto full = trace(scene, start, shape, w, k, &*traced, kNearDiff);
  if (!full) return std::nullopt;
  const Vec3 to_target = towards_target(*full, k, target);
  if (!same_direction(full->d, to_target)) return std::nullopt;
  const auto fmiss = [&](const Traced& c) { return forward_miss(c, k, target); };
  double J[2][2];
  if (!derivative(scene, start, shape, w, *full, frame_across(w), frame_across(full->d),
                  fmiss(*full), k, fmiss, J))
    return std::nullopt;
  SpecularChain chain;
  chain.solid = shape.solid;
  chain.vertices = k;
  for (int v = 0; v < k; ++v) {
    chain.x[v] = full->x[v];
    chain.n[v] = full->n[v];
  }
  chain.dir0 = w;
  chain.dir_out = full->d;
  chain.transmission = full->transmission;
  chain.jacobian = 1 / std::abs(J[0][0] * J[1][1] - J[0][1] * J[1][0]);  // |dω₀/dA⊥|, |dω₀/dω|
  if (!std::isfinite(chain.jacobian)) return std::nullopt;
  ++counters.found;
  return chain;
}

bool same_direction(const Vec3& a, const Vec3& b) {
  return dot(a, b) > 1 - 1e-10;
}

}  // namespace nimbus
