#pragma once
// Manifold next-event estimation in the path loop (render/integrator.h): light that reaches a
// medium or diffuse vertex through one smooth dielectric solid's boundary (render/manifold.h),
// and the partition of path space that keeps it from counting twice with BSDF and phase
// sampling. The light sample is next-event estimation's own: where its straight shadow ray
// meets a dielectric solid first (or leaves the solid the vertex is in), the chain through that
// solid to the same light point replaces the shadow ray, which would be blocked. Emissive
// surfaces, which next-event estimation does not sample, have a walk of their own at each vertex
// to a point sampled on one of them (render/emitter.h), used only where the straight ray meets a
// dielectric solid first. A path sampled from the vertex that reaches a sphere light or an
// emissive surface through the same refractions counts only where that walk, repeated for the
// point it hit, would not have found it (manifold_covers, manifold_covers_surface): the two
// estimators share no path, and together miss none that sampling can find.

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "nimbus/math/constants.h"
#include "nimbus/media/medium_field.h"
#include "nimbus/render/emitter.h"
#include "nimbus/render/light.h"
#include "nimbus/render/light_choice.h"
#include "nimbus/render/manifold.h"
#include "nimbus/render/path_spectra.h"
#include "nimbus/render/scene.h"
#include "nimbus/render/tracking_policies.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

// What a path did since it left its last diffuse or medium vertex, for manifold_covers.
struct ChainRecord {
  ChainStart start;
  Vec3 dir0;       // the direction it left in
  int solid = -1;  // the solid it refracted through, or -1
  int refractions = 0;
  bool open = false;  // it met only refractions through one solid since (and the setting is on)

  // A new vertex the path leaves in direction w.
  static ChainRecord leaving(const ChainStart& start, const Vec3& w, bool manifold) {
    return {start, w, -1, 0, manifold};
  }
  // The path met a smooth dielectric boundary of `object`.
  void specular(int object, bool reflected) {
    if (reflected || (solid >= 0 && solid != object) || ++refractions > kMaxChainVertices)
      open = false;
    solid = object;
  }
};

// The target of a light sample for the walk: the point it sampled (point and sphere lights) or
// the direction (directional); none for the environment, which BSDF sampling serves.
inline std::optional<ChainTarget> chain_target(const Light& light, const Vec3& p,
                                               const LightSample& ls) {
  switch (light.type) {
    case Light::Type::Directional:
      return ChainTarget{{}, ls.wi, true};
    case Light::Type::Point:
      return ChainTarget{light.position, {}, false};
    case Light::Type::Sphere:
      return ChainTarget{p + ls.wi * ls.distance, {}, false};
    case Light::Type::Environment:
      break;
  }
  return std::nullopt;
}

// The probability of making the walk for a light sample (docs/media.md, "Light through smooth
// boundaries"): exp(−τ), τ the optical depth that the octrees' minorants give the seed's path
// to the boundary and, for two refractions, its straight chord through the solid: about a
// bound on the chain's transmittance over every channel. Where a dense medium absorbs the
// chain's light on the way, walking every time lost at equal time (the bench's marble and skin,
// the demo); the estimate is divided by it, so the image does not change. It is at least
// kMinWalkProbability: the seed's path may be far longer than the chain's (a free form's
// one-refraction seed), and 1/q then multiplied a chain that lost little light into a sparkle
// (single samples up to 159 in scenes/translucent.json); the floor was also the more efficient
// on the bench's marble (+4 %), skin (+8 %) and the demo (+15 %).
inline constexpr double kMinWalkProbability = 0.05;

template <int N>
double walk_probability(const Scene& scene, const PathSpectra<N>& ps, const ChainStart& start,
                        const ChainShape& shape, const ChainSeed& seed) {
  double tau = 0;
  const auto add = [&](const MajorantSegment<N>& seg) {
    tau += seg.mu_c.min() * (seg.t1 - seg.t0);
    return true;
  };
  const Ray ray{start.p, seed.w};
  walk_majorant_segments(scene, ps.ch, ray, 0, seed.t_first, start.inside, add);
  if (seed.t_through > 0)
    walk_majorant_segments(scene, ps.ch, ray, seed.t_first, seed.t_first + seed.t_through,
                           shape.solid, add);
  return std::max(kMinWalkProbability, std::exp(-tau));
}

// What a chain ends on: a light (point, sphere, directional), or an emissive surface.
struct ChainEnd {
  int light = -1;
  int object = -1;
};

// The light through one specular chain from `start` to `target` times the scattering function f
// at the chain's first direction and the policy's transmittance of its segments, divided by
// choice_pdf. `emitted(chain)` is the radiance the light sends back along the chain's last
// direction per the target's density (what turns the walk's geometry term into the vertex's
// measure). Uses the path's stream for the transmittance.
template <int N, class Policy, class F, class Emitted>
Spectrum<N> manifold_term(const Scene& scene, const PathSpectra<N>& ps, const ChainStart& start,
                          const ChainShape& shape, const ChainTarget& target, const ChainSeed& seed,
                          const ChainEnd& end, Emitted&& emitted, double choice_pdf,
                          const Policy& policy, F&& f, Rng& rng, Counters& counters) {
  const auto chain = solve_chain(scene, start, target, shape, seed, counters.manifold);
  if (!chain) return Spectrum<N>(0.0);
  const Spectrum<N> fv = f(chain->dir0);
  if (fv.is_black()) return Spectrum<N>(0.0);
  const Spectrum<N> Le = emitted(*chain);
  if (Le.is_black()) return Spectrum<N>(0.0);
  const Spectrum<N> fLi = fv * Le * (chain->jacobian * chain->transmission / choice_pdf);
  // The straight segments: start to the boundary, across the solid, out to the light.
  std::array<ShadowSegment, kMaxChainVertices + 1> segments;
  const int k = chain->vertices;
  Vec3 o = start.on_surface ? offset_origin(scene, start.p, start.n, chain->dir0) : start.p;
  Vec3 d = chain->dir0;
  int inside = start.inside;
  for (int v = 0; v < k; ++v) {
    segments[size_t(v)] = {{o, d}, length(chain->x[v] - o) * kShadowShrink, inside, -1};
    d = v + 1 < k ? normalize(chain->x[v + 1] - chain->x[v]) : chain->dir_out;
    o = offset_origin(scene, chain->x[v], chain->n[v], d);
    inside = v + 1 < k ? shape.solid : -1;
  }
  double t_last = target.at_infinity ? kInf : length(target.point - o) * kShadowShrink;
  if (end.object >= 0) {
    // The walk's last direction is the target's to within its tolerance, so the ray may meet the
    // surface a little before the target: it must meet it there first.
    const auto hit = intersect(scene, {o, d}, kInf);
    if (!hit || hit->object != end.object || std::abs(hit->t - t_last) > 1e-4 * t_last)
      return Spectrum<N>(0.0);
    t_last = hit->t * kShadowShrink;
  }
  segments[size_t(k)] = {{o, d}, t_last, -1, end.light};
  Spectrum<N> out;
  if (!policy.chain_term(scene, ps, std::span<const ShadowSegment>(segments.data(), size_t(k + 1)),
                         fLi, rng, counters, out))
    return Spectrum<N>(0.0);
  return out;
}

// What light i sends back along a chain to its sample ls from p (manifold_term's `emitted`):
// its emission, times for a sphere light cos_y / pdf_A, the point having been sampled in the cone
// the light subtends from p (area density pdf_ω cos / d² there; the chain leaves it at cos_y).
// The walk's geometry term is then E |dω₀/dω| for a directional light, I |dω₀/dA⊥| for a point.
template <int N>
Spectrum<N> light_chain_emission(const Scene& scene, const PathSpectra<N>& ps, int i,
                                 const ChainTarget& target, const LightSample& ls,
                                 const SpecularChain& chain) {
  const Light& light = scene.lights[size_t(i)];
  double g = 1;
  if (light.type == Light::Type::Sphere) {
    const Vec3 n_y = normalize(target.point - light.center);
    const double cos_y = dot(n_y, -chain.dir_out), cos_p = dot(n_y, -ls.wi);
    const double pdf_area = ls.pdf * cos_p / (ls.distance * ls.distance);
    if (!(cos_y > 0) || !(pdf_area > 0)) return Spectrum<N>(0.0);
    g = cos_y / pdf_area;
  }
  return light_emission(ps, scene, i) * g;
}

// What an emissive surface of radiance Le sends back along a chain to its point e: Le times
// cos_y / pdf_A (render/emitter.h), where the chain meets its outer side.
template <int N>
Spectrum<N> surface_chain_emission(const Spectrum<N>& Le, const EmitterPoint& e,
                                   const SpecularChain& chain) {
  const double cos_y = dot(e.n, -chain.dir_out);
  if (!(cos_y > 0)) return Spectrum<N>(0.0);
  return Le * (cos_y / e.pdf_area);
}

// Whether a chain through shape's solid can reach the emitter's point e on its outer side: its
// last segment leaves the solid's boundary, so some corner of the solid's bounds must lie in
// front of the tangent plane at e. Half of the points sampled on a compact emitter fail this,
// and a walk to them, which could only find a chain that arrives from behind, costs as much as
// any other.
inline bool may_arrive_in_front(const Scene& scene, const ChainShape& shape,
                                const EmitterPoint& e) {
  const Box& b = scene.objects[size_t(shape.solid)].bounds;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner{c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y, c & 4 ? b.hi.z : b.lo.z};
    if (dot(e.n, corner - e.y) > 0) return true;
  }
  return false;
}

// Whether the walk takes a chain of `vertices` refractions to a light with an area (a sphere
// light, an emissive surface): through a solid from outside (a caustic) only with
// integrator.manifold_area_caustics. At equal time such walks won against BSDF sampling on some
// scenes and lost on others (docs/benchmarks.md); point and directional lights have no other
// technique, so they always walk.
inline bool walks_to_area(const Scene& scene, int vertices) {
  return vertices == 1 || scene.settings.manifold_area_caustics;
}

// Whether manifold sampling targets the scene's emissive surfaces: the walk to them is a
// strategy of its own at each vertex, with its own slot of sampler dimensions.
inline bool walks_to_emitters(const Scene& scene) {
  return scene.settings.manifold && scene.dielectric_solids && !scene.emitters.empty();
}

namespace manifold_detail {

// Whether the walk from the record's start to y goes through the same refractions to the same
// first direction as the sampled path did.
inline bool walk_finds(const Scene& scene, const ChainRecord& chain, const Vec3& y,
                       Counters& counters) {
  const int vertices = chain.start.inside >= 0 ? 1 : 2;
  const ChainTarget target{y, {}, false};
  const auto shape = chain_shape(scene, chain.start, target);
  if (!shape || shape->solid != chain.solid || shape->vertices != vertices) return false;
  ++counters.manifold.checks;
  ManifoldCounters not_counted;  // a check is not a walk of next-event estimation
  const auto found = solve_chain(scene, chain.start, target, *shape,
                                 seed_chain(scene, chain.start, target, *shape), not_counted);
  return found && same_direction(found->dir0, chain.dir0);
}

// Whether the record is a chain of refractions through one solid that the walk could have made.
inline bool walkable(const Scene& scene, const ChainRecord& chain) {
  const int vertices = chain.start.inside >= 0 ? 1 : 2;
  return chain.open && chain.refractions == vertices && walks_to_area(scene, vertices);
}

}  // namespace manifold_detail

// Whether manifold next-event estimation at the record's start covers the sampled path that
// reached sphere light i at y: it picks the light there, samples y, and its walk for y goes
// through the same refractions to the same first direction. Such a path is then counted by the
// walk alone.
template <int N>
bool manifold_covers(const Scene& scene, const PathSpectra<N>& ps, const ChainRecord& chain, int i,
                     const Vec3& y, Counters& counters) {
  if (!manifold_detail::walkable(scene, chain)) return false;
  const Light& light = scene.lights[size_t(i)];
  if (light.type != Light::Type::Sphere) return false;
  const Vec3 p = chain.start.p;
  if (scene.settings.light_sampling == RenderSettings::LightSampling::One &&
      !(light_choice_pdf(scene, ps, i, p) > 0))
    return false;
  // Next-event estimation samples the point the straight ray from p meets first, in the cone.
  const double dist = length(y - p);
  const Vec3 dir = (y - p) / dist;
  if (!(light_pdf(light, p, dir) > 0)) return false;
  const auto t = intersect_light(light, {p, dir}, 0, kInf);
  if (!t || std::abs(*t - dist) > 1e-6 * dist) return false;
  return manifold_detail::walk_finds(scene, chain, y, counters);
}

// The same for a sampled path that reached the emissive surface of `object` at y (outward normal
// n): the walk to emitters samples y with positive density there (render/emitter.h).
inline bool manifold_covers_surface(const Scene& scene, const ChainRecord& chain, int object,
                                    const Vec3& y, const Vec3& n, Counters& counters) {
  if (!walks_to_emitters(scene) || !manifold_detail::walkable(scene, chain)) return false;
  if (!(emitter_point_pdf(scene, object, y, n) > 0)) return false;
  return manifold_detail::walk_finds(scene, chain, y, counters);
}

}  // namespace nimbus
