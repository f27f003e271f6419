#pragma once
// The path tracer: radiance arriving along a camera ray, at a path's N channels
// (render/path_spectra.h). One path loop for every tracking mode, which is a policy
// (render/tracking_policies.h). Instantiated per channel count (render/render_channels.cpp.in)
// and per policy (with_tracking_policy).

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "nimbus/math/constants.h"
#include "nimbus/math/ray.h"
#include "nimbus/math/rng.h"
#include "nimbus/media/medium_field.h"
#include "nimbus/render/counters.h"
#include "nimbus/render/first_vertex.h"
#include "nimbus/render/glossy.h"
#include "nimbus/render/light_choice.h"
#include "nimbus/render/manifold_light.h"
#include "nimbus/render/mirror_light.h"
#include "nimbus/render/path_sampler.h"
#include "nimbus/render/path_spectra.h"
#include "nimbus/render/sampling.h"
#include "nimbus/render/scene.h"
#include "nimbus/render/tracking_policies.h"
#include "nimbus/render/volume.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {
namespace integrator_detail {

// A light sample for next-event estimation at p with the scattering function's value there and
// the shadow ray's origin; none if the light cannot contribute.
template <int N>
struct LightCandidate {
  LightSample ls;
  Spectrum<N> f;
  Spectrum<N> Li;  // falloff times the light's emission at the path's channels
  Vec3 origin;
};

template <int N, class F>
std::optional<LightCandidate<N>> light_candidate(const Scene& scene, const PathSpectra<N>& ps,
                                                 int light_index, const LightSample& ls,
                                                 const ChainStart& at, F&& f) {
  if (at.on_surface && at.boundary < 0 && dot(ls.wi, at.n) <= 0) return std::nullopt;
  const Spectrum<N> fv = f(ls.wi);
  if (fv.is_black()) return std::nullopt;
  return LightCandidate<N>{ls, fv, light_emission(ps, scene, light_index) * ls.falloff,
                           at.on_surface ? offset_origin(scene, at.p, at.n, ls.wi) : at.p};
}

// The light slots of a bounce's sampler dimensions (SampleDims::bounce): one per light, or with
// one light per vertex, the chosen light's and a slot whose first number picks it; then one for
// a point on an emissive surface, where the scene has one.
inline int light_slots(const Scene& scene) {
  const int lights = static_cast<int>(scene.lights.size());
  return (scene.settings.light_sampling == RenderSettings::LightSampling::One ? std::min(lights, 2)
                                                                              : lights) +
         (scene.emitters.empty() ? 0 : 1);
}

// The probability with which next-event estimation at p samples light i: 1 when every light is
// sampled.
template <int N>
double light_sampling_pdf(const Scene& scene, const PathSpectra<N>& ps, int i, const Vec3& p) {
  return scene.settings.light_sampling == RenderSettings::LightSampling::One
             ? light_choice_pdf(scene, ps, i, p)
             : 1.0;
}

// Light reaching the vertex `at` by next-event estimation, times the scattering function
// `f(wi)` (cosine included for surfaces) and the policy's weight for the shadow ray (its
// transmittance, and MIS with the sampling of f): one sample of every light, or of one light
// picked by its fluence at the vertex (light_choice.h), divided by the probability of the pick.
// A light's numbers come from its slot in the block of `bounce` (SampleDims::light; the picked
// light takes slot 0, the pick slot 1). With `manifold`, a sample whose straight shadow ray
// leaves the solid the vertex is in, or meets a dielectric solid first, is joined to the light
// through that solid's boundary instead (render/manifold_light.h), and a point on one emissive
// surface is joined the same way, from the slot after the lights' (render/emitter.h); without
// it, a vertex inside a solid has no next-event estimation (its boundary is specular), and the
// caller skips it.
template <int N, class Policy, class F, class Pdf>
Spectrum<N> direct_light(const Scene& scene, const PathSpectra<N>& ps, const ChainStart& at,
                         int depth, bool manifold, const Policy& policy, F&& f, Pdf&& f_pdf,
                         PathSampler& sampler, uint32_t bounce, Counters& counters) {
  Spectrum<N> L(0.0);
  // Light i from slot `slot`, picked with probability choice_pdf.
  auto sample = [&](int i, int slot, double choice_pdf) {
    const uint32_t dims = SampleDims::light(bounce, slot);
    const std::array<double, 2> u = sampler.get2d(dims + SampleDims::kLightPoint);
    const Light& light = scene.lights[size_t(i)];
    const auto sampled = sample_light(light, at.p, u[0], u[1]);
    if (!sampled) return;
    if (manifold) {
      const auto target = chain_target(light, at.p, *sampled);
      const auto shape = target ? chain_shape(scene, at, *target) : std::nullopt;
      if (shape) {
        // The straight shadow ray is blocked; a caustic of an area light is BSDF sampling's.
        if (!sampled->delta && !walks_to_area(scene, shape->vertices)) return;
        // The same path sampled by f would take `vertices` more bounces (MIS's weights).
        if (depth + shape->vertices >= scene.settings.max_depth) return;
        sampler.first_from(dims + SampleDims::kShadow);
        Rng& rng = sampler.rng();
        const ChainSeed seed = seed_chain(scene, at, *target, *shape);
        const double q = walk_probability(scene, ps, at, *shape, seed) *
                         (shape->vertices == 2 && !sampled->delta
                              ? caustic_walk_share(at.p, light.center, light.radius)
                              : 1.0);
        const auto emitted = [&](const SpecularChain& c) {
          return light_chain_emission(scene, ps, i, *target, *sampled, c);
        };
        if (rng.uniform() < q)
          L += manifold_term<N>(scene, ps, at, *shape, *target, seed, {i, -1}, emitted,
                                choice_pdf * q, policy, f, f_pdf, rng, counters);
        sampler.done();
        return;
      }
    }
    auto cand = light_candidate(scene, ps, i, *sampled, at, f);
    if (!cand) return;
    LightSample& ls = cand->ls;
    // The light technique's pdf includes the pick; a delta light's weight has no pdf to carry it.
    if (ls.delta)
      cand->Li /= choice_pdf;
    else
      ls.pdf *= choice_pdf;
    Spectrum<N> term;
    sampler.first_from(dims + SampleDims::kShadow);
    const bool lit = policy.light_term(scene, ps, {cand->origin, ls.wi},
                                       ls.distance * kShadowShrink, i, side_of(at, ls.wi), ls,
                                       cand->f * cand->Li, f_pdf, sampler.rng(), counters, term);
    sampler.done();
    if (lit) L += term;
  };
  const int lights = static_cast<int>(scene.lights.size());
  if (scene.settings.light_sampling == RenderSettings::LightSampling::One && lights > 1) {
    const auto [i, choice_pdf] =
        choose_light(scene, ps, at.p, sampler.get1d(SampleDims::light(bounce, 1)));
    sample(i, 0, choice_pdf);
  } else {
    for (int i = 0; i < lights; ++i) sample(i, i, 1.0);
  }
  if (!scene.emitters.empty()) {
    // A point on one emissive surface, picked uniformly, from the slot after the lights'
    // (render/emitter.h): joined by a walk where the straight ray meets a dielectric solid first,
    // else by a shadow ray, weighted by MIS with the sampling of f (a vertex inside a solid has
    // none: its boundary is specular).
    const uint32_t dims = SampleDims::light(bounce, light_slots(scene) - 1);
    const std::array<double, 2> u = sampler.get2d(dims + SampleDims::kLightPoint);
    sampler.first_from(dims + SampleDims::kShadow);
    Rng& rng = sampler.rng();
    const int emitters = static_cast<int>(scene.emitters.size());
    const int object =
        scene.emitters[size_t(std::min(emitters - 1, static_cast<int>(rng.uniform() * emitters)))];
    const auto e = sample_emitter_point(scene, object, u[0], u[1], rng.uniform());
    const ChainTarget target{e ? e->y : Vec3{}, {}, false};
    const auto shape = e && manifold ? chain_shape(scene, at, target) : std::nullopt;
    const Spectrum<N> Le = evaluate(scene.objects[size_t(object)].surface.radiance, ps.ch);
    if (shape) {
      if (depth + shape->vertices < scene.settings.max_depth &&
          walks_to_area(scene, shape->vertices) && may_arrive_in_front(scene, *shape, *e)) {
        const ChainSeed seed = seed_chain(scene, at, target, *shape);
        const double q = walk_probability(scene, ps, at, *shape, seed) *
                         (shape->vertices == 2 ? emitter_walk_share(scene, object, at.p) : 1.0);
        const auto emitted = [&](const SpecularChain& c) {
          return surface_chain_emission(Le, *e, c);
        };
        if (rng.uniform() < q)
          L += manifold_term<N>(scene, ps, at, *shape, target, seed, {-1, object}, emitted,
                                q / emitters, policy, f, f_pdf, rng, counters);
      }
    } else if (e) {
      const Vec3 to = e->y - at.p;
      const double d = length(to);
      const Vec3 wi = to / d;
      const double cos_y = dot(e->n, -wi);
      if (cos_y > 0 && d > 0 && side_of(at, wi) < 0 &&
          !(at.on_surface && at.boundary < 0 && dot(wi, at.n) <= 0)) {
        const Spectrum<N> fv = f(wi);
        LightSample ls{wi, d, 1.0, e->pdf_area * d * d / cos_y / emitters, false};
        // The shadow ray runs from its own origin to just short of the point: the emitter
        // blocks it anywhere past that.
        const Vec3 o = at.on_surface ? offset_origin(scene, at.p, at.n, wi) : at.p;
        const double t = length(e->y - o);
        Spectrum<N> term;
        if (!fv.is_black() && ls.pdf > 0 && std::isfinite(ls.pdf) &&
            policy.light_term(scene, ps, {o, (e->y - o) / t}, t * kShadowShrink, -1, -1, ls,
                              fv * Le, f_pdf, rng, counters, term))
          L += term;
      }
    }
    sampler.done();
  }
  return L;
}

// A scattering direction from the mixture phase function at a medium point, with its
// per-channel weight (phase value / pdf) and pdf.
template <int N>
struct PhaseSample {
  Vec3 wi;
  Spectrum<N> weight;
  double pdf;
};

// The lobe from dimension `bounce` + kChoice, the direction from `bounce` + kDirection.
template <int N>
PhaseSample<N> draw_phase(const MediumPoint<N>& m, const Vec3& dir, PathSampler& sampler,
                          uint32_t bounce) {
  const double u0 = sampler.get1d(bounce + SampleDims::kChoice);
  const std::array<double, 2> u = sampler.get2d(bounce + SampleDims::kDirection);
  PhaseSample<N> ps;
  ps.wi = sample_phase(m, dir, u0, u[0], u[1], ps.weight, ps.pdf);
  return ps;
}

}  // namespace integrator_detail

// The one path loop: radiance along a camera ray, with the tracking mode's policy
// (tracking_policies.h) for what differs between modes. Each bounce takes its numbers from its
// block of the sampler's dimensions (SampleDims), the tracking estimators from the path's stream.
// With `first`, also what the path met first, for the AOVs (render/first_vertex.h); recording
// draws no number, so the radiance is the same bits with or without it.
template <int N, class Policy>
Spectrum<N> trace_path(const Scene& scene, const PathSpectra<N>& ps, Ray ray, PathSampler& sampler,
                       Counters& counters, Policy& policy, FirstVertex* first = nullptr) {
  using namespace integrator_detail;
  ++counters.paths;
  FirstVertexRecorder record(first);
  Rng& rng = sampler.rng();
  const int slots = light_slots(scene);  // per bounce, in the sampler's dimensions
  Spectrum<N> L(0.0);
  int inside = solid_containing(scene, ray.o);  // the solid (dielectric) the path is in, or -1
  // The last vertex sampled the lights (next-event estimation), so a light the path hits next
  // is weighted by MIS; false at the camera, at specular surfaces and inside solids.
  bool light_sampled = false;
  // The last vertex sampled emissive surfaces by a shadow ray (it is outside every solid), so a
  // surface the path hits next is weighted by MIS.
  bool emitters_sampled = false;
  Vec3 prev_p = ray.o;  // where the current direction was sampled
  // Manifold next-event estimation (render/manifold_light.h), where the scene has something it
  // looks through; `chain` is what the path did since its last diffuse or medium vertex.
  const bool manifold = scene.settings.manifold && scene.dielectric_solids;
  ChainRecord chain;
  // The last vertex probed its mirror direction and the path took it: what that ray meets emits
  // nothing more (render/mirror_light.h).
  bool mirror_probed = false;

  for (int depth = 0;; ++depth) {
    const uint32_t bounce = SampleDims::bounce(depth, slots);
    const bool emission_counted = std::exchange(mirror_probed, false);
    // Roulette's number is drawn only when roulette plays (the independent sampler's order).
    const auto roulette_u = [&] { return sampler.get1d(bounce + SampleDims::kRoulette); };
    ++counters.surface_rays;
    const auto hit = intersect(scene, ray, kInf);
    const double t_surface = hit ? hit->t : kInf;
    sampler.first_from(bounce + SampleDims::kFreeFlight);
    const MediumEvent<N> ev = policy.collide(scene, ps, ray, t_surface, inside, rng, counters);
    sampler.done();
    L += ev.emitted;
    if (ev.type != MediumEvent<N>::Type::None) record.medium(scene, ray, ev.t, inside);
    if (ev.type == MediumEvent<N>::Type::Absorb) break;
    if (ev.type == MediumEvent<N>::Type::Scatter) {
      if (depth >= scene.settings.max_depth) break;
      const Vec3 p = ray.at(ev.t);
      const MediumPoint<N>& m = ev.medium;
      const ChainStart at{p, {}, false, inside};
      // Without manifold sampling no shadow ray leaves a solid, whose boundary is specular: a
      // light is then found from inside by phase sampling alone, with weight 1. With it, a light
      // the straight shadow ray reaches inside the solid is sampled too, and weighted by MIS.
      if (inside < 0 || manifold)
        L += policy.throughput() *
             direct_light(
                 scene, ps, at, depth, manifold, policy,
                 [&](const Vec3& wi) { return phase_value(m, dot(ray.d, wi)); },
                 [&](const Vec3& wi) { return phase_pdf(m, dot(ray.d, wi)); }, sampler, bounce,
                 counters);
      const PhaseSample<N> phase = draw_phase(m, ray.d, sampler, bounce);
      policy.scattered(phase.weight, phase.pdf);
      prev_p = p;
      light_sampled = inside < 0 || manifold;
      emitters_sampled = inside < 0;
      chain = ChainRecord::leaving(at, phase.wi, manifold);
      ray = {p, phase.wi};
      if (!policy.roulette(depth, roulette_u)) break;
      continue;
    }

    if (!hit) {
      record.escape();
      if (!emission_counted)
        for (const int i : scene.lights_at_infinity)
          L += policy.light_hit(light_emission(ps, scene, i), scene.lights[i], prev_p, ray.d,
                                light_sampled, light_sampling_pdf(scene, ps, i, prev_p));
      break;
    }
    if (hit->light >= 0) {
      record.light(scene.lights[hit->light], ray, hit->t);
      if (!emission_counted) {
        const Spectrum<N> Le = light_emission(ps, scene, hit->light);
        // A path through a smooth boundary that manifold sampling at its last vertex finds too
        // is weighted against the walk.
        const double walk =
            manifold_light_pdf(scene, ps, chain, hit->light, ray.at(hit->t), counters);
        L += walk > 0 ? policy.emission(Le, true, walk)
                      : policy.light_hit(Le, scene.lights[hit->light], prev_p, ray.d, light_sampled,
                                         light_sampling_pdf(scene, ps, hit->light, prev_p));
      }
      break;
    }
    const SceneObject& obj = scene.objects[hit->object];
    const Vec3 p = ray.at(hit->t);
    const Vec3 n = outward_normal(obj, p);
    record.surface(scene, obj, ray, hit->t, n);
    if (obj.surface.type == Surface::Type::Emissive) {
      // As for a sphere light: what the walk to emissive surfaces finds too is weighted against
      // it.
      if (!emission_counted && dot(ray.d, n) < 0) {
        const double walk = manifold_surface_pdf(scene, ps, chain, hit->object, p, n, counters);
        L += walk > 0
                 ? policy.emission(evaluate(obj.surface.radiance, ps.ch), true, walk)
                 : policy.emission(evaluate(obj.surface.radiance, ps.ch), emitters_sampled,
                                   emitters_sampled
                                       ? emitter_solid_angle_pdf(scene, hit->object, prev_p, p, n)
                                       : 0);
      }
      break;
    }
    if (depth >= scene.settings.max_depth) break;

    if (obj.surface.type == Surface::Type::Diffuse) {
      const Vec3 ns = dot(ray.d, n) < 0 ? n : -n;  // facing the incoming ray
      Spectrum<N> albedo = evaluate(obj.surface.albedo, ps.ch);
      if (obj.surface.albedo_texture) [[unlikely]]
        albedo += (evaluate(obj.surface.albedo_to, ps.ch) - albedo) *
                  obj.surface.albedo_texture.at(texture_point(scene, obj, p), 0.0);
      const Spectrum<N> f = albedo * kInvPi;
      const ChainStart at{p, ns, true, inside};
      L += policy.throughput() * direct_light(
                                     scene, ps, at, depth, manifold, policy,
                                     [&](const Vec3& wi) { return f * dot(wi, ns); },
                                     [&](const Vec3& wi) { return dot(wi, ns) * kInvPi; }, sampler,
                                     bounce, counters);
      const std::array<double, 2> u = sampler.get2d(bounce + SampleDims::kDirection);
      const Vec3 wi = sample_cosine_hemisphere(ns, u[0], u[1]);
      policy.scattered(albedo, dot(wi, ns) * kInvPi);  // f cos / pdf = albedo
      prev_p = p;
      light_sampled = true;
      emitters_sampled = inside < 0;
      chain = ChainRecord::leaving(at, wi, manifold);
      ray = {offset_origin(scene, p, ns, wi), wi};
    } else if (obj.surface.roughness > 0) {
      // A rough conductor or dielectric (render/glossy.h): next-event estimation with MIS, to
      // both sides of a dielectric boundary (the shadow ray in the medium of its side), then a
      // direction sampled from the microfacet lobe. Manifold sampling does not start here.
      const Vec3 wo = -ray.d;
      const bool two_sided = obj.surface.type == Surface::Type::Dielectric;
      const ChainStart at{p, two_sided || dot(wo, n) > 0 ? n : -n, true, inside,
                          two_sided ? hit->object : -1};
      const double alpha = roughness_at(obj.surface, texture_point(scene, obj, p));
      std::optional<MicrofacetAlbedo> blended;
      const Glossy<N> g(obj.surface, alpha, ps, at.n,
                        obj.albedo ? obj.albedo->at(alpha, blended) : nullptr);
      L += policy.throughput() *
           direct_light(
               scene, ps, at, depth, false, policy,
               [&](const Vec3& wi) { return g.f(wo, wi) * std::abs(dot(wi, n)); },
               [&](const Vec3& wi) { return g.pdf(wo, wi); }, sampler, bounce, counters);
      const std::array<double, 2> u = sampler.get2d(bounce + SampleDims::kDirection);
      const auto gs = g.sample(wo, sampler.get1d(bounce + SampleDims::kChoice), u[0], u[1]);
      if (!gs) break;
      policy.scattered(gs->weight, gs->pdf);
      prev_p = p;
      light_sampled = true;
      emitters_sampled = side_of(at, gs->wi) < 0;
      chain = ChainRecord::leaving(at, gs->wi, false);
      if (two_sided) inside = side_of(at, gs->wi);
      ray = {offset_origin(scene, p, n, gs->wi), gs->wi};
    } else if (obj.surface.type == Surface::Type::Conductor) {
      // A smooth conductor: the mirror direction, weighted by its Fresnel reflectance.
      const Vec3 nf = dot(ray.d, n) < 0 ? n : -n;
      const Vec3 wi = ray.d - nf * (2 * dot(ray.d, nf));
      policy.scattered(conductor_fresnel(evaluate(obj.surface.eta, ps.ch),
                                         evaluate(obj.surface.k, ps.ch), -dot(ray.d, nf)),
                       1.0);
      light_sampled = false;
      emitters_sampled = false;
      chain.specular(hit->object, true);
      ray = {offset_origin(scene, p, nf, wi), wi};
    } else {
      const DielectricSample ds = sample_dielectric(-ray.d, n, obj.surface.ior,
                                                    sampler.get1d(bounce + SampleDims::kChoice));
      if (manifold && probes_mirror(ds, ray.d, n)) {
        L += policy.throughput() *
             mirror_light(scene, ps, p, n, ray.d, ds.F, inside, policy, rng, counters);
        mirror_probed = ds.reflected;
      }
      if (!ds.reflected) inside = dot(ds.wi, n) < 0 ? hit->object : -1;
      light_sampled = false;
      emitters_sampled = false;
      chain.specular(hit->object, ds.reflected);
      ray = {offset_origin(scene, p, n, ds.wi), ds.wi};
    }
    if (!policy.roulette(depth, roulette_u)) break;
  }
  return L;
}

}  // namespace nimbus
