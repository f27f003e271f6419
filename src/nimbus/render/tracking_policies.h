#pragma once
// The tracking modes as policies of the one path loop (render/integrator.h). A policy owns the
// path's per-path state and answers what differs between the modes: the next real collision
// along a ray, the weight of a light found by next-event estimation (its shadow ray's
// transmittance and MIS), the weight of a light or an emitter the path hits, the update of its
// throughput at a scattering vertex, and Russian roulette. Everything else (surfaces, lights,
// phase sampling, the order of random numbers) is the loop's, once.
//
// - PlainTracking<N, Flight>: delta tracking, spectral-max and spectral-history (one throughput
//   beta; power-heuristic MIS between light sampling and BSDF or phase sampling), with the
//   free-path estimator Flight (render/volume.h: Woodcock, decomposition or weighted tracking).
// - HeroTracking: null-scattering spectral MIS (Miller et al. 2019): a hero channel per path,
//   path pdfs r_u and r_l, the balance heuristic over channels and techniques.
//
// A render's tracking settings are resolved once, by with_tracking_policy, into the policy type
// its paths run with; the path loop is instantiated per policy. Adding a tracking mode: a policy
// with these members (docs/architecture.md), a name in render/setting_names.h, and its case in
// with_tracking_policy.

#include <algorithm>
#include <span>

#include "nimbus/math/rng.h"
#include "nimbus/render/counters.h"
#include "nimbus/render/light.h"
#include "nimbus/render/path_sampler.h"
#include "nimbus/render/path_spectra.h"
#include "nimbus/render/sampling.h"
#include "nimbus/render/scene.h"
#include "nimbus/render/volume.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

// Continues the path with probability q = min(1, max|beta / scale|) from depth 3 on; u() gives
// the uniform number, called only when roulette plays.
template <int N, class U>
bool russian_roulette(Spectrum<N>& beta, double scale, int depth, U&& u) {
  if (depth < 3) return true;
  const double q = std::min(1.0, beta.max_abs() / scale);
  if (q <= 0 || u() >= q) return false;
  beta /= q;  // unbiased: survivors carry 1/q
  return true;
}

// One straight segment of a specular chain's shadow path (render/manifold.h), in the medium of
// `inside` (a solid, or -1 for the field), aimed at `light` (-1: it ends on a boundary).
struct ShadowSegment {
  Ray ray;
  double t_max;
  int inside;
  int light;
};

template <int N, class Flight>
class PlainTracking {
 public:
  // The rule and absorption events of the render's mode; the Channel rule's channel is the
  // path's, chosen where it first meets a medium.
  explicit PlainTracking(const EventPolicy& events) : events_(events) { events_.channel = -1; }

  // The path throughput, which multiplies next-event estimates.
  const Spectrum<N>& throughput() const { return beta_; }

  MediumEvent<N> collide(const Scene& scene, const PathSpectra<N>& ps, const Ray& ray, double t_max,
                         int inside, Rng& rng, Counters& counters) {
    return sample_collision<N, Flight>(scene, ps, ray, t_max, inside, events_, beta_, boost_, rng,
                                       counters);
  }

  // Next-event estimation of one light sample `ls` along `shadow` (to t_max): fLi is the
  // scattering function times the light's incident radiance; f_pdf the scattering pdf of the
  // direction. False where the light is blocked.
  template <class Pdf>
  bool light_term(const Scene& scene, const PathSpectra<N>& ps, const Ray& shadow, double t_max,
                  int light, int inside, const LightSample& ls, const Spectrum<N>& fLi, Pdf&& f_pdf,
                  Rng& rng, Counters& counters, Spectrum<N>& out) const {
    const Spectrum<N> T = transmittance(scene, ps, shadow, t_max, light, inside, events_.channel,
                                        boost_, beta_ * fLi, rng, counters);
    if (T.is_black()) return false;
    out = ls.delta ? fLi * T : fLi * T * (power_heuristic(ls.pdf, f_pdf(ls.wi)) / ls.pdf);
    return true;
  }

  // Next-event estimation along a specular chain found by manifold sampling: the transmittance
  // of its segments, each in its own medium. fLi is already divided by the walk's density p_w;
  // rho = p_f / p_w, the density with which sampling f would take the same path over it, weighs
  // the two by the power heuristic (render/manifold_light.h); 0 for a delta light, whose chain
  // is the only technique for its paths.
  bool chain_term(const Scene& scene, const PathSpectra<N>& ps,
                  std::span<const ShadowSegment> segments, const Spectrum<N>& fLi, double rho,
                  Rng& rng, Counters& counters, Spectrum<N>& out) const {
    Spectrum<N> T(1.0);
    for (const ShadowSegment& s : segments) {
      T *= transmittance(scene, ps, s.ray, s.t_max, s.light, s.inside, events_.channel, boost_,
                         beta_ * fLi * T, rng, counters);
      if (T.is_black()) return false;
    }
    out = fLi * T * power_heuristic(1.0, rho);
    return true;
  }

  // Radiance Le of `light` reached along dir from prev_p; `light_sampled`: the vertex there
  // sampled the lights too, picking this one with probability choice_pdf.
  Spectrum<N> light_hit(const Spectrum<N>& Le, const Light& light, const Vec3& prev_p,
                        const Vec3& dir, bool light_sampled, double choice_pdf) const {
    return beta_ * Le *
           (light_sampled ? power_heuristic(prev_pdf_, choice_pdf * light_pdf(light, prev_p, dir))
                          : 1.0);
  }

  // Radiance Le of an emissive surface the path hits; `light_sampled`: the vertex before sampled
  // a point on it too, with solid-angle density light_pdf (render/emitter.h).
  Spectrum<N> emission(const Spectrum<N>& Le, bool light_sampled, double light_pdf) const {
    return beta_ * Le * (light_sampled ? power_heuristic(prev_pdf_, light_pdf) : 1.0);
  }

  // A scattering vertex: the throughput times weight (f cos / pdf), the direction drawn with pdf.
  void scattered(const Spectrum<N>& weight, double pdf) {
    beta_ *= weight;
    prev_pdf_ = pdf;
  }

  template <class U>
  bool roulette(int depth, U&& u) {
    return russian_roulette(beta_, 1.0, depth, u);
  }

 private:
  Spectrum<N> beta_{1.0};
  // Delta tracking (the Channel rule) follows one channel per path, events_.channel, chosen
  // uniformly when the path first meets a medium (sample_collision), and from then on carries
  // its weight (times N) in that channel; -1 until then, and for the other rules.
  EventPolicy events_;
  double prev_pdf_ = 0;  // solid-angle pdf with which the current direction was sampled
  double boost_ = 1;     // the path's majorant boost (volume.h)
};

template <int N>
class HeroTracking {
 public:
  // u: the uniform number that picks the hero channel.
  explicit HeroTracking(double u) : hero_(std::min(N - 1, static_cast<int>(u * N))) {}

  const Spectrum<N>& throughput() const { return path_.beta; }

  MediumEvent<N> collide(const Scene& scene, const PathSpectra<N>& ps, const Ray& ray, double t_max,
                         int inside, Rng& rng, Counters& counters) {
    return sample_collision_mis(scene, ps, ray, t_max, inside, hero_, path_, boost_, rng, counters);
  }

  // Miller et al. 2019, §6 (pbrt-v4's SampleLd): the shadow ray's T_ray, r_u and r_l from hero
  // ratio tracking, the vertex pdfs folded in with the path's r_u, and the balance heuristic over
  // channels and both techniques:
  //   f Li T_ray / avg(r_u (p_light r_l + p_f r_u)),  or f Li T_ray / avg(r_u r_l) for delta
  //   lights.
  template <class Pdf>
  bool light_term(const Scene& scene, const PathSpectra<N>& ps, const Ray& shadow, double t_max,
                  int light, int inside, const LightSample& ls, const Spectrum<N>& fLi, Pdf&& f_pdf,
                  Rng& rng, Counters& counters, Spectrum<N>& out) const {
    MisPath<N> s;
    if (!transmittance_mis(scene, ps, shadow, t_max, light, inside, hero_, boost_, path_.beta * fLi,
                           s, rng, counters))
      return false;
    const Spectrum<N>& r_p = path_.r_u;
    if (ls.delta) {
      out = fLi * s.beta / (r_p * s.r_l).average();
    } else {
      const Spectrum<N> r_l = r_p * s.r_l * ls.pdf, r_u = r_p * s.r_u * f_pdf(ls.wi);
      out = fLi * s.beta / (r_l + r_u).average();
    }
    return true;
  }

  // As PlainTracking::chain_term: hero ratio tracking over every segment into one T_ray, r_u and
  // r_l, weighted as light_term's with the pdfs over p_w: f Li T_ray / avg(r_u (r_l + ρ r_u)).
  bool chain_term(const Scene& scene, const PathSpectra<N>& ps,
                  std::span<const ShadowSegment> segments, const Spectrum<N>& fLi, double rho,
                  Rng& rng, Counters& counters, Spectrum<N>& out) const {
    MisPath<N> s;
    for (const ShadowSegment& seg : segments)
      if (!transmittance_mis(scene, ps, seg.ray, seg.t_max, seg.light, seg.inside, hero_, boost_,
                             path_.beta * fLi, s, rng, counters))
        return false;
    out = fLi * s.beta / (path_.r_u * (s.r_l + s.r_u * rho)).average();
    return true;
  }

  Spectrum<N> light_hit(const Spectrum<N>& Le, const Light& light, const Vec3& prev_p,
                        const Vec3& dir, bool light_sampled, double choice_pdf) const {
    if (!light_sampled) return path_.beta * Le / path_.r_u.average();
    const Spectrum<N> r_l = path_.r_l * (choice_pdf * light_pdf(light, prev_p, dir));
    return path_.beta * Le / (path_.r_u + r_l).average();
  }

  Spectrum<N> emission(const Spectrum<N>& Le, bool light_sampled, double light_pdf) const {
    if (!light_sampled) return path_.beta * Le / path_.r_u.average();
    return path_.beta * Le / (path_.r_u + path_.r_l * light_pdf).average();
  }

  void scattered(const Spectrum<N>& weight, double pdf) {
    path_.beta *= weight;
    path_.r_l = path_.r_u / pdf;
  }

  template <class U>
  bool roulette(int depth, U&& u) {
    return russian_roulette(path_.beta, path_.r_u.average(), depth, u);
  }

 private:
  int hero_;
  MisPath<N> path_;
  double boost_ = 1;  // the path's majorant boost (volume.h)
};

// The collision rule and absorption events of a plain mode (not spectral-mis).
inline EventPolicy event_policy(const TrackingSettings& t) {
  using Mode = TrackingSettings::Mode;
  EventPolicy events;
  events.rule = t.mode == Mode::Delta             ? EventRule::Channel
                : t.mode == Mode::SpectralHistory ? EventRule::History
                                                  : EventRule::Max;
  events.absorption_events = t.absorption == TrackingSettings::Absorption::Collide;
  return events;
}

// Calls f with a factory of the policy that the tracking settings select: a callable that takes
// the path's sampler and returns a fresh policy for it. Resolved once per render; f is
// instantiated per policy type.
template <int N, class F>
decltype(auto) with_tracking_policy(const TrackingSettings& t, F&& f) {
  if (t.mode == TrackingSettings::Mode::SpectralMis)
    return f(
        [](PathSampler& sampler) { return HeroTracking<N>(sampler.get1d(SampleDims::kHero)); });
  const EventPolicy events = event_policy(t);
  // The classic baseline: Woodcock's delta tracking, with absorption events, without
  // decomposition.
  if (events.rule == EventRule::Channel && events.absorption_events && !t.decomposition)
    return f([events](PathSampler&) { return PlainTracking<N, WoodcockFlight>(events); });
  if (t.decomposition)
    return f([events](PathSampler&) { return PlainTracking<N, DecompositionFlight>(events); });
  return f([events](PathSampler&) { return PlainTracking<N, WeightedFlight>(events); });
}

}  // namespace nimbus
