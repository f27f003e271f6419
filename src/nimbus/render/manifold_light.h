#pragma once
// Manifold next-event estimation in the path loop (render/integrator.h): light that reaches a
// medium or diffuse vertex through one smooth dielectric solid's boundary (render/manifold.h),
// and its MIS weights against BSDF and phase sampling. The light sample is next-event estimation's
// own: where its straight shadow ray meets a dielectric solid first (or leaves the solid the vertex
// is in), the chain through that solid to the same light point replaces the shadow ray, which would
// be blocked. Emissive surfaces, which next-event estimation does not sample, have a walk of their
// own at each vertex to a point sampled on one of them (render/emitter.h), used only where the
// straight ray meets a dielectric solid first. A path sampled from the vertex that reaches a sphere
// light or an emissive surface through the same refractions is weighted against the walk by the
// power heuristic where that walk, repeated for the point it hit, finds the same chain, and counts
// alone where it would not (manifold_light_pdf, manifold_surface_pdf). The walk is
// deterministic, so its density for a path is the light sample's, carried to the vertex's
// solid angle by the chain's geometry term.

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

// What a path did since it left its last diffuse or medium vertex, for the MIS weights of its light
// hits.
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

// The share of caustic walks (two refractions, through a solid from outside) to a light with an
// area that are made, for a light of bounding sphere (center, radius) seen from p: BSDF
// sampling finds such a chain about in proportion to the solid angle Ω the light subtends,
// while a walk costs the same whatever the light's size, so walks are made with probability
// min(1, Ω₀ / Ω). It is part of the walk's density, so MIS weighs it in and the image does not
// change. Ω₀ from the bench (docs/benchmarks.md, "Light through smooth boundaries").
inline constexpr double kCausticSolidAngle = 0.01;  // Ω₀, steradians (a 3.2° radius)
inline double caustic_walk_share(const Vec3& p, const Vec3& center, double radius) {
  const Vec3 to = center - p;
  const double d2 = dot(to, to), r2 = radius * radius;
  const double omega = d2 > r2 ? 2 * kPi * (1 - std::sqrt(1 - r2 / d2)) : 4 * kPi;
  return std::min(1.0, kCausticSolidAngle / omega);
}

// The same for the emissive surface of `object`, whose bounding sphere is its bounds'.
inline double emitter_walk_share(const Scene& scene, int object, const Vec3& p) {
  const Box& b = scene.objects[size_t(object)].bounds;
  return caustic_walk_share(p, b.center(), 0.5 * length(b.extent()));
}

// What a chain ends on: a light (point, sphere, directional), or an emissive surface.
struct ChainEnd {
  int light = -1;
  int object = -1;
};

// What a light sends back along a chain (manifold_term's `emitted`): its radiance per the
// target's density, and that density in the area across the chain's last direction,
// pdf_A / cos_y (0 for a delta light, which no other technique samples).
template <int N>
struct ChainEmission {
  Spectrum<N> Le;
  double pdf_perp = 0;
};

// The walk's density for a chain in the solid angle of its first direction, divided by the
// chain's transmission: the light sample's density pdf_perp, carried by the geometry term
// |dω₀/dA⊥|, times the probability choice_pdf of picking the light and walking. MIS compares it
// with the scattering pdf at the chain's start (the transmission is the probability that
// sampling then takes every refraction).
inline double walk_pdf(const SpecularChain& chain, double pdf_perp, double choice_pdf) {
  return choice_pdf * pdf_perp / (chain.jacobian * chain.transmission);
}

// The light through one specular chain from `start` to `target` times the scattering function f
// at the chain's first direction and the policy's transmittance of its segments, divided by
// choice_pdf; for a target with an area, weighted by the power heuristic against sampling f
// (pdf f_pdf). `emitted(chain)` is what the light sends back along the chain's last direction
// (ChainEmission). Uses the path's stream for the transmittance.
template <int N, class Policy, class F, class Pdf, class Emitted>
Spectrum<N> manifold_term(const Scene& scene, const PathSpectra<N>& ps, const ChainStart& start,
                          const ChainShape& shape, const ChainTarget& target, const ChainSeed& seed,
                          const ChainEnd& end, Emitted&& emitted, double choice_pdf,
                          const Policy& policy, F&& f, Pdf&& f_pdf, Rng& rng, Counters& counters) {
  const auto chain = solve_chain(scene, start, target, shape, seed, counters.manifold);
  if (!chain) return Spectrum<N>(0.0);
  const Spectrum<N> fv = f(chain->dir0);
  if (fv.is_black()) return Spectrum<N>(0.0);
  const ChainEmission<N> e = emitted(*chain);
  if (e.Le.is_black()) return Spectrum<N>(0.0);
  const Spectrum<N> fLi = fv * e.Le * (chain->jacobian * chain->transmission / choice_pdf);
  const double rho =
      e.pdf_perp > 0 ? f_pdf(chain->dir0) / walk_pdf(*chain, e.pdf_perp, choice_pdf) : 0.0;
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
                         fLi, rho, rng, counters, out))
    return Spectrum<N>(0.0);
  return out;
}

// The area density with which next-event estimation from p samples the point y of sphere light
// i: its cone's solid-angle density times cos / d² at y (n_y, the outward normal there).
inline double sphere_point_pdf(const Light& light, const Vec3& p, const Vec3& y, const Vec3& n_y) {
  const Vec3 to = y - p;
  const double d2 = dot(to, to), d = std::sqrt(d2);
  return light_pdf(light, p, to / d) * dot(n_y, -to / d) / d2;
}

// What light i sends back along a chain to its sample ls from p (manifold_term's `emitted`):
// its emission, times for a sphere light cos_y / pdf_A, the point having been sampled in the cone
// the light subtends from p; the chain leaves it at cos_y. The walk's geometry term is then
// E |dω₀/dω| for a directional light, I |dω₀/dA⊥| for a point.
template <int N>
ChainEmission<N> light_chain_emission(const Scene& scene, const PathSpectra<N>& ps, int i,
                                      const ChainTarget& target, const LightSample& ls,
                                      const SpecularChain& chain) {
  const Light& light = scene.lights[size_t(i)];
  if (light.type != Light::Type::Sphere) return {light_emission(ps, scene, i), 0.0};
  const Vec3 n_y = normalize(target.point - light.center);
  const double cos_y = dot(n_y, -chain.dir_out), cos_p = dot(n_y, -ls.wi);
  const double pdf_area = ls.pdf * cos_p / (ls.distance * ls.distance);
  if (!(cos_y > 0) || !(pdf_area > 0)) return {Spectrum<N>(0.0), 0.0};
  return {light_emission(ps, scene, i) * (cos_y / pdf_area), pdf_area / cos_y};
}

// What an emissive surface of radiance Le sends back along a chain to its point e: Le times
// cos_y / pdf_A (render/emitter.h), where the chain meets its outer side.
template <int N>
ChainEmission<N> surface_chain_emission(const Spectrum<N>& Le, const EmitterPoint& e,
                                        const SpecularChain& chain) {
  const double cos_y = dot(e.n, -chain.dir_out);
  if (!(cos_y > 0)) return {Spectrum<N>(0.0), 0.0};
  return {Le * (cos_y / e.pdf_area), e.pdf_area / cos_y};
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

// The chain the walk from the record's start to y finds, where it goes through the same
// refractions to the same first direction as the sampled path did, with the probability of
// making that walk (walk_probability).
struct FoundChain {
  SpecularChain chain;
  double q;
};
template <int N>
std::optional<FoundChain> walk_finds(const Scene& scene, const PathSpectra<N>& ps,
                                     const ChainRecord& chain, const Vec3& y, double caustic_share,
                                     Counters& counters) {
  const int vertices = chain.start.inside >= 0 ? 1 : 2;
  const ChainTarget target{y, {}, false};
  const auto shape = chain_shape(scene, chain.start, target);
  if (!shape || shape->solid != chain.solid || shape->vertices != vertices) return std::nullopt;
  ++counters.manifold.checks;
  ManifoldCounters not_counted;  // a check is not a walk of next-event estimation
  const ChainSeed seed = seed_chain(scene, chain.start, target, *shape);
  const auto found = solve_chain(scene, chain.start, target, *shape, seed, not_counted);
  if (!found || !same_direction(found->dir0, chain.dir0)) return std::nullopt;
  const double share = vertices == 2 ? caustic_share : 1.0;
  return FoundChain{*found, share * walk_probability(scene, ps, chain.start, *shape, seed)};
}

// Whether the record is a chain of refractions through one solid that the walk could have made.
inline bool walkable(const Scene& scene, const ChainRecord& chain) {
  const int vertices = chain.start.inside >= 0 ? 1 : 2;
  return chain.open && chain.refractions == vertices && walks_to_area(scene, vertices);
}

}  // namespace manifold_detail

// The density (walk_pdf) with which manifold next-event estimation at the record's start
// samples the path that reached sphere light i at y: it picks the light there, samples y, and
// its walk for y goes through the same refractions to the same first direction; 0 where it
// would not. The path is then weighted against it by the power heuristic.
template <int N>
double manifold_light_pdf(const Scene& scene, const PathSpectra<N>& ps, const ChainRecord& chain,
                          int i, const Vec3& y, Counters& counters) {
  if (!manifold_detail::walkable(scene, chain)) return 0;
  const Light& light = scene.lights[size_t(i)];
  if (light.type != Light::Type::Sphere) return 0;
  const Vec3 p = chain.start.p;
  const double choice_pdf = scene.settings.light_sampling == RenderSettings::LightSampling::One
                                ? light_choice_pdf(scene, ps, i, p)
                                : 1.0;
  if (!(choice_pdf > 0)) return 0;
  // Next-event estimation samples the point the straight ray from p meets first, in the cone.
  const double dist = length(y - p);
  const Vec3 dir = (y - p) / dist;
  if (!(light_pdf(light, p, dir) > 0)) return 0;
  const auto t = intersect_light(light, {p, dir}, 0, kInf);
  if (!t || std::abs(*t - dist) > 1e-6 * dist) return 0;
  const auto found = manifold_detail::walk_finds(
      scene, ps, chain, y, caustic_walk_share(p, light.center, light.radius), counters);
  if (!found) return 0;
  const Vec3 n_y = normalize(y - light.center);
  const double cos_y = dot(n_y, -found->chain.dir_out);
  if (!(cos_y > 0)) return 0;
  return walk_pdf(found->chain, sphere_point_pdf(light, p, y, n_y) / cos_y, choice_pdf * found->q);
}

// The same for a sampled path that reached the emissive surface of `object` at y (outward normal
// n): the walk to emitters picks one uniformly and samples y on it (render/emitter.h).
template <int N>
double manifold_surface_pdf(const Scene& scene, const PathSpectra<N>& ps, const ChainRecord& chain,
                            int object, const Vec3& y, const Vec3& n, Counters& counters) {
  if (!walks_to_emitters(scene) || !manifold_detail::walkable(scene, chain)) return 0;
  const double pdf_area = emitter_point_pdf(scene, object, y, n);
  if (!(pdf_area > 0)) return 0;
  const auto found = manifold_detail::walk_finds(
      scene, ps, chain, y, emitter_walk_share(scene, object, chain.start.p), counters);
  if (!found) return 0;
  const double cos_y = dot(n, -found->chain.dir_out);
  if (!(cos_y > 0)) return 0;
  return walk_pdf(found->chain, pdf_area / cos_y,
                  found->q / static_cast<double>(scene.emitters.size()));
}

}  // namespace nimbus
