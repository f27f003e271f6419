#pragma once
// The integrator's view of the media along a ray: where the next real collision is, and how much
// light gets through. Both walk the majorant segments of the medium field with the estimators of
// tracking/ that the scene's tracking settings select (docs/media.md), on a path's N channels.

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "nimbus/math/rng.h"
#include "nimbus/media/medium_field.h"
#include "nimbus/render/counters.h"
#include "nimbus/render/glow.h"
#include "nimbus/render/path_spectra.h"
#include "nimbus/render/scene.h"
#include "nimbus/tracking/decomposition_tracking.h"
#include "nimbus/tracking/delta_tracking.h"
#include "nimbus/tracking/ray_marching_transmittance.h"
#include "nimbus/tracking/spectral_mis.h"
#include "nimbus/tracking/spectral_tracking.h"
#include "nimbus/tracking/transmittance.h"

namespace nimbus {

template <int N>
struct MediumEvent {
  enum class Type { None, Scatter, Absorb };
  Type type = Type::None;
  double t = 0;
  MediumPoint<N> medium;     // the coefficients at the collision
  Spectrum<N> emitted{0.0};  // radiance emitted by the media on the way, weighted by the path
};

// A path's majorant boost: the factor on every majorant its free flights and shadow rays track
// with. An estimator that finds mu_t above its majorant raises it for the rest of that segment
// (tracking/free_flight.h, raise_majorant); where that happens the path's boost is multiplied by
// kBoostOnRaise, so that later rays of the same path do not pay again where the majorants fail
// by a factor (a majorant scale below 1, a sampled majorant that missed the maximum): the
// boost stops growing once the boosted majorants bound. Boosts depend only on the path itself,
// never on other samples, so images stay the same whatever the threads or processes.
inline constexpr double kBoostOnRaise = 2;

namespace volume_detail {

// L_e = mu_a_Le / mu_a where mu_a > 0, else 0.
template <int N>
Spectrum<N> emission(const Spectrum<N>& mu_a, const Spectrum<N>& mu_a_Le) {
  Spectrum<N> L_e(0.0);
  for (int c = 0; c < N; ++c)
    if (mu_a_Le[c] != 0 && mu_a[c] > 0) L_e[c] = mu_a_Le[c] / mu_a[c];
  return L_e;
}

template <int N>
MediumSample<N> as_sample(const MediumPoint<N>& m) {
  return {m.mu_a, m.mu_s, emission(m.mu_a, m.mu_a_Le)};
}

// The coefficients at a point of a shadow ray: no phase functions.
template <int N>
MediumSample<N> shadow_sample(const Scene& scene, const PathSpectra<N>& ps, const Vec3& x,
                              int inside) {
  MediumSample<N> s;
  Spectrum<N> mu_a_Le;
  medium_sums_at(scene, ps.media, x, inside, s.mu_a, s.mu_s, mu_a_Le);
  s.L_e = emission(s.mu_a, mu_a_Le);
  return s;
}

// The medium along a ray, keeping the last point looked up: the one at the collision that ends
// tracking.
template <int N>
struct RayLookup {
  const Scene& scene;
  const PathSpectra<N>& ps;
  const Ray& ray;
  int inside;
  MediumPoint<N> last;
  // Where the scene glows (render/glow.h): the path weight the flights update, what the
  // emission is added to, and the last point looked up. Each lookup is a tentative collision,
  // made in order along the ray, before the flight reweights there: the weight holds over the
  // interval since the last one.
  Spectrum<N>* beta = nullptr;
  Spectrum<N>* emitted = nullptr;
  Rng* rng = nullptr;
  double t_glow = 0;
  MediumSample<N> operator()(double t) {
    if (beta) glow_to(t);
    medium_at(scene, ps.media, ray.at(t), inside, last);
    return as_sample(last);
  }
  // Scores the emission per unit length over (t_glow, t) at the current weight.
  void glow_to(double t) {
    glow_samples(scene, ps, ray, inside, t_glow, t, *rng,
                 [&](double, const Spectrum<N>& len_j) { *emitted += *beta * len_j; });
    t_glow = t;
  }
};

// Fills in the event of a real collision at t; `at` is the lookup made there.
template <int N>
MediumEvent<N> real_event(const Collision& c, const MediumPoint<N>& at, Counters& counters) {
  MediumEvent<N> ev;
  ++counters.real_collisions;
  ev.t = c.t;
  ev.medium = at;
  if (c.event == CollisionEvent::Scatter) {
    ++counters.scatter_events;
    ev.type = MediumEvent<N>::Type::Scatter;
  } else {
    ev.type = MediumEvent<N>::Type::Absorb;
  }
  return ev;
}

// Adds the lookups made during its lifetime to counters.shadow_lookups.
struct ShadowLookups {
  Counters& counters;
  uint64_t before = counters.tracking.lookups;
  ~ShadowLookups() { counters.shadow_lookups += counters.tracking.lookups - before; }
};

}  // namespace volume_detail

// The free-path estimators of the plain modes over one majorant segment [t0, t1] at rate
// mu_bar, one type each. A render resolves its tracking settings once into one of them
// (tracking_policies.h), and the path loop is instantiated per type: no segment asks which.
// `events` is the collision rule and whether absorption is an event
// (tracking/weighted_collision.h).

// Woodcock's delta tracking (rule Channel with absorption events, no decomposition): the classic
// baseline, which clamps where mu_bar does not bound.
struct WoodcockFlight {
  template <int N>
  static Collision track(volume_detail::RayLookup<N>& lookup, const MajorantSegment<N>& seg,
                         double mu_bar, const EventPolicy& events, Spectrum<N>& beta,
                         Spectrum<N>& emitted, Rng& rng, TrackingCounters& counters) {
    const Collision c =
        delta_tracking<N>(lookup, seg.t0, seg.t1, mu_bar, events.channel, rng, counters);
    if (c.event == CollisionEvent::Absorb)
      emitted += beta * volume_detail::as_sample(lookup.last).L_e;
    return c;
  }
};

// Decomposition tracking: the minorant's part sampled analytically, the rest by weighted
// tentative collisions (docs/media.md).
struct DecompositionFlight {
  template <int N>
  static Collision track(volume_detail::RayLookup<N>& lookup, const MajorantSegment<N>& seg,
                         double mu_bar, const EventPolicy& events, Spectrum<N>& beta,
                         Spectrum<N>& emitted, Rng& rng, TrackingCounters& counters) {
    return decomposition_tracking<N>(lookup, seg.t0, seg.t1, seg.mu_c.min(), mu_bar, events, beta,
                                     emitted, rng, counters);
  }
};

// Spectral tracking: one free path for every channel, weighted collisions (eq. 6-13).
struct WeightedFlight {
  template <int N>
  static Collision track(volume_detail::RayLookup<N>& lookup, const MajorantSegment<N>& seg,
                         double mu_bar, const EventPolicy& events, Spectrum<N>& beta,
                         Spectrum<N>& emitted, Rng& rng, TrackingCounters& counters) {
    return spectral_tracking<N>(lookup, seg.t0, seg.t1, mu_bar, events, beta, emitted, rng,
                                counters);
  }
};

// The next real collision over (0, t_max) of the ray (unit direction) by the estimator Flight,
// for every mode but spectral-mis. `beta`, the path throughput, is updated by the tracking
// weights. Rule Channel (delta tracking): one channel per path; `events.channel` -1 means none is
// chosen yet: where the ray meets a medium one is drawn uniformly, and beta keeps that channel
// only (times N). Rules Max and History: every channel along one free path. `boost` is the
// path's majorant boost (kBoostOnRaise), grown here where a majorant failed.
template <int N, class Flight>
MediumEvent<N> sample_collision(const Scene& scene, const PathSpectra<N>& ps, const Ray& ray,
                                double t_max, int inside, EventPolicy& events, Spectrum<N>& beta,
                                double& boost, Rng& rng, Counters& counters) {
  const bool one_channel = events.rule == EventRule::Channel;
  volume_detail::RayLookup<N> lookup{scene, ps, ray, inside, {}};
  Spectrum<N> emitted(0.0);
  const bool glows = !scene.glowing_objects.empty();
  if (glows) {
    lookup.beta = &beta;
    lookup.emitted = &emitted;
    lookup.rng = &rng;
  }
  MediumEvent<N> ev;
  walk_majorant_segments(scene, ps.ch, ray, 0, t_max, inside, [&](const MajorantSegment<N>& seg) {
    ++counters.majorant_segments;
    // The Channel rule picks its channel where the path first meets a medium and reweights.
    if (one_channel && events.channel < 0) {
      events.channel = std::min(N - 1, static_cast<int>(rng.uniform() * N));
      const double b = beta[events.channel];
      beta = Spectrum<N>(0.0);
      beta[events.channel] = N * b;
    }
    const double mu_bar = boost * (one_channel ? seg.mu_bar[events.channel] : seg.mu_bar.max());
    const uint64_t raised = counters.tracking.raised;
    const Collision c = Flight::template track<N>(lookup, seg, mu_bar, events, beta, emitted, rng,
                                                  counters.tracking);
    if (counters.tracking.raised != raised) boost *= kBoostOnRaise;
    if (c.event == CollisionEvent::Escape) return true;
    ev = volume_detail::real_event(c, lookup.last, counters);
    return false;
  });
  if (glows && ev.type == MediumEvent<N>::Type::None) lookup.glow_to(t_max);
  ev.emitted = emitted;
  return ev;
}

// spectral-mis: the next real collision with hero channel `hero`, updating beta, r_u and r_l, and
// the path's majorant boost.
template <int N>
MediumEvent<N> sample_collision_mis(const Scene& scene, const PathSpectra<N>& ps, const Ray& ray,
                                    double t_max, int inside, int hero, MisPath<N>& path,
                                    double& boost, Rng& rng, Counters& counters) {
  volume_detail::RayLookup<N> lookup{scene, ps, ray, inside, {}};
  Spectrum<N> emitted(0.0);
  MediumEvent<N> ev;
  // Emission per unit length (render/glow.h) inside the segments by hero_tracking, and between
  // them (no majorant: the path's weights hold) here.
  auto glow = [&](double a, double b, auto&& f) {
    glow_samples(scene, ps, ray, inside, a, b, rng, f);
  };
  double t_done = 0;  // where the last segment ended
  walk_majorant_segments(scene, ps.ch, ray, 0, t_max, inside, [&](const MajorantSegment<N>& seg) {
    ++counters.majorant_segments;
    score_glow(glow, t_done, seg.t0, Spectrum<N>(0.0), hero, path, emitted);
    t_done = seg.t1;
    const uint64_t raised = counters.tracking.raised;
    const Collision c = hero_tracking<N>(lookup, seg.t0, seg.t1, seg.mu_bar * boost, hero, path,
                                         emitted, rng, counters.tracking, glow);
    if (counters.tracking.raised != raised) boost *= kBoostOnRaise;
    if (c.event == CollisionEvent::Escape) return true;
    ev = volume_detail::real_event(c, lookup.last, counters);
    return false;
  });
  if (ev.type == MediumEvent<N>::Type::None)
    score_glow(glow, t_done, t_max, Spectrum<N>(0.0), hero, path, emitted);
  ev.emitted = emitted;
  return ev;
}

// Transmittance over (0, t_max) by ratio, residual ratio tracking or unbiased ray marching
// (settings.transmittance),
// and 0 if a surface blocks the way. `light` is the light the shadow ray aims at (it does not
// block), or -1. `channel` >= 0 (delta tracking once it has chosen its channel): the path's
// throughput is in that channel alone, so only it is tracked, at its own majorant, with
// roulette on its own estimate; the other channels come back 0. -1: every channel, at the
// largest majorant. The majorants are multiplied by the path's `boost`. `weight` is what multiplies
// T in the contribution (throughput times the scattering function and the light): Russian
// roulette plays on the share of it that T still carries (transmittance_roulette).
template <int N>
Spectrum<N> transmittance(const Scene& scene, const PathSpectra<N>& ps, const Ray& ray,
                          double t_max, int light, int inside, int channel, double boost,
                          const Spectrum<N>& weight, Rng& rng, Counters& counters) {
  ++counters.shadow_rays;
  if (occluded(scene, ray, t_max, light)) return Spectrum<N>(0.0);
  const volume_detail::ShadowLookups count{counters};
  auto lookup = [&](double t) {
    return volume_detail::shadow_sample(scene, ps, ray.at(t), inside);
  };
  using Estimator = TrackingSettings::Transmittance;
  const Estimator estimator = scene.settings.tracking.transmittance;
  if (estimator == Estimator::RayMarching) {
    // The whole ray's segments first: the marches spread their points over all of them. The
    // estimator needs no bounding majorant, so the boost does not apply.
    thread_local std::vector<MarchSegment<N>> segs;
    segs.clear();
    walk_majorant_segments(scene, ps.ch, ray, 0, t_max, inside, [&](const MajorantSegment<N>& s) {
      ++counters.majorant_segments;
      segs.push_back({s.t0, s.t1, s.mu_bar, s.mu_c});
      return true;
    });
    return ray_marching_transmittance<N>(lookup, std::span<const MarchSegment<N>>(segs), channel,
                                         rng, counters.tracking, &weight);
  }
  Spectrum<N> T(channel < 0 ? 1.0 : 0.0);
  if (channel >= 0) T[channel] = 1;
  // The largest value over the tracked channels.
  auto tracked_max = [&](const Spectrum<N>& x) { return channel < 0 ? x.max() : x[channel]; };
  // Each segment updates T by `track`, until T is 0.
  auto walk = [&](auto&& track) {
    walk_majorant_segments(scene, ps.ch, ray, 0, t_max, inside, [&](const MajorantSegment<N>& seg) {
      ++counters.majorant_segments;
      T = track(seg);
      return !T.is_black();
    });
  };
  if (estimator == Estimator::ResidualRatio) {
    walk([&](const MajorantSegment<N>& seg) {
      // The residual's rate must bound |mu_t − mu_c|; a scaled majorant may fall below mu_c.
      const Spectrum<N> gap = abs(seg.mu_bar * boost - seg.mu_c);
      return residual_ratio_tracking<N>(lookup, seg.t0, seg.t1, seg.mu_c, tracked_max(gap), rng,
                                        counters.tracking, T, &weight);
    });
  } else {
    walk([&](const MajorantSegment<N>& seg) {
      return ratio_tracking<N>(lookup, seg.t0, seg.t1, boost * tracked_max(seg.mu_bar), rng,
                               counters.tracking, T, &weight);
    });
  }
  return T;
}

// spectral-mis: the shadow ray's T_ray, r_u and r_l (in `path`, which starts at 1), by hero ratio
// tracking, with roulette on the share of `weight` (what multiplies the transmittance in the
// contribution) that it carries. False if a surface blocks the way or T_ray became 0.
template <int N>
bool transmittance_mis(const Scene& scene, const PathSpectra<N>& ps, const Ray& ray, double t_max,
                       int light, int inside, int hero, double boost, const Spectrum<N>& weight,
                       MisPath<N>& path, Rng& rng, Counters& counters) {
  ++counters.shadow_rays;
  if (occluded(scene, ray, t_max, light)) return false;
  const volume_detail::ShadowLookups count{counters};
  auto lookup = [&](double t) {
    return volume_detail::shadow_sample(scene, ps, ray.at(t), inside);
  };
  bool reaches = true;
  walk_majorant_segments(scene, ps.ch, ray, 0, t_max, inside, [&](const MajorantSegment<N>& seg) {
    ++counters.majorant_segments;
    reaches = hero_ratio_tracking<N>(lookup, seg.t0, seg.t1, seg.mu_bar * boost, hero, path, rng,
                                     counters.tracking, &weight);
    return reaches;
  });
  return reaches;
}

}  // namespace nimbus
