#include "nimbus/render/volume.h"

#include <algorithm>

#include "nimbus/tracking/decomposition_tracking.h"
#include "nimbus/tracking/delta_tracking.h"
#include "nimbus/tracking/spectral_tracking.h"
#include "nimbus/tracking/transmittance.h"

namespace nimbus {
namespace {

using Mode = TrackingSettings::Mode;

MediumSample<3> as_sample(const MediumPoint& m) {
  MediumSample<3> s{m.mu_a, m.mu_s, Rgb(0.0)};
  for (int c = 0; c < 3; ++c) s.L_e[c] = m.mu_a[c] > 0 ? m.mu_a_Le[c] / m.mu_a[c] : 0.0;
  return s;
}

// The medium along a ray, keeping the last point looked up: the one at the collision that ends
// tracking.
struct RayLookup {
  const Scene& scene;
  const Ray& ray;
  int inside;
  MediumPoint last;
  MediumSample<3> operator()(double t) {
    last = medium_at(scene, ray.at(t), inside);
    return as_sample(last);
  }
};

// Fills in the event of a real collision at t; `at` is the lookup made there.
MediumEvent real_event(const Collision& c, const MediumPoint& at, Counters& counters) {
  MediumEvent ev;
  ++counters.real_collisions;
  ev.t = c.t;
  ev.medium = at;
  if (c.event == CollisionEvent::Scatter) {
    ++counters.scatter_events;
    ev.type = MediumEvent::Type::Scatter;
  } else {
    ev.type = MediumEvent::Type::Absorb;
  }
  return ev;
}

}  // namespace

MediumEvent sample_collision(const Scene& scene, const Ray& ray, double t_max, int inside,
                             Rgb& beta, int& channel, Rng& rng, Counters& counters) {
  const TrackingSettings& ts = scene.settings.tracking;
  const bool delta = ts.mode == Mode::Delta;
  EventPolicy policy;
  policy.rule = delta                              ? EventRule::Channel
                : ts.mode == Mode::SpectralHistory ? EventRule::History
                                                   : EventRule::Max;
  policy.absorption_events = ts.absorption == TrackingSettings::Absorption::Collide;
  // The classic baseline: Woodcock's delta tracking, which clamps where mu_bar does not bound.
  const bool woodcock = delta && policy.absorption_events && !ts.decomposition;

  RayLookup lookup{scene, ray, inside, {}};
  Rgb emitted(0.0);
  MediumEvent ev;
  walk_majorant_segments(scene, ray, 0, t_max, inside, [&](const MajorantSegment& seg) {
    ++counters.majorant_segments;
    // Delta tracking picks its channel where the path first meets a medium and reweights.
    if (delta && channel < 0) {
      channel = std::min(2, static_cast<int>(rng.uniform() * 3));
      const double b = beta[channel];
      beta = Rgb(0.0);
      beta[channel] = 3 * b;
    }
    policy.channel = std::max(channel, 0);
    const double mu_bar = delta ? seg.mu_bar[channel] : seg.mu_bar.max();
    Collision c;
    if (woodcock) {
      c = delta_tracking<3>(lookup, seg.t0, seg.t1, mu_bar, channel, rng, counters.tracking);
      if (c.event == CollisionEvent::Absorb) emitted = beta * as_sample(lookup.last).L_e;
    } else if (ts.decomposition) {
      c = decomposition_tracking<3>(lookup, seg.t0, seg.t1, seg.mu_c.min(), mu_bar, policy, beta,
                                    emitted, rng, counters.tracking);
    } else {
      c = spectral_tracking<3>(lookup, seg.t0, seg.t1, mu_bar, policy, beta, emitted, rng,
                               counters.tracking);
    }
    if (c.event == CollisionEvent::Escape) return true;
    ev = real_event(c, lookup.last, counters);
    return false;
  });
  ev.emitted = emitted;
  return ev;
}

MediumEvent sample_collision_mis(const Scene& scene, const Ray& ray, double t_max, int inside,
                                 int hero, MisPath<3>& path, Rng& rng, Counters& counters) {
  RayLookup lookup{scene, ray, inside, {}};
  Rgb emitted(0.0);
  MediumEvent ev;
  walk_majorant_segments(scene, ray, 0, t_max, inside, [&](const MajorantSegment& seg) {
    ++counters.majorant_segments;
    const Collision c = hero_tracking<3>(lookup, seg.t0, seg.t1, seg.mu_bar, hero, path, emitted,
                                         rng, counters.tracking);
    if (c.event == CollisionEvent::Escape) return true;
    ev = real_event(c, lookup.last, counters);
    return false;
  });
  ev.emitted = emitted;
  return ev;
}

Rgb transmittance(const Scene& scene, const Ray& ray, double t_max, int light, int inside, Rng& rng,
                  Counters& counters) {
  ++counters.shadow_rays;
  if (occluded(scene, ray, t_max, light)) return Rgb(0.0);
  auto lookup = [&](double t) { return as_sample(medium_at(scene, ray.at(t), inside)); };
  const bool residual =
      scene.settings.tracking.transmittance == TrackingSettings::Transmittance::ResidualRatio;
  Rgb T(1.0);
  walk_majorant_segments(scene, ray, 0, t_max, inside, [&](const MajorantSegment& seg) {
    ++counters.majorant_segments;
    if (residual) {
      // The residual's rate must bound |mu_t − mu_c|; a scaled majorant may fall below mu_c.
      double mu_bar_r = 0;
      for (int c = 0; c < 3; ++c)
        mu_bar_r = std::max(mu_bar_r, std::abs(seg.mu_bar[c] - seg.mu_c[c]));
      T = residual_ratio_tracking<3>(lookup, seg.t0, seg.t1, seg.mu_c, mu_bar_r, rng,
                                     counters.tracking, T);
    } else {
      T = ratio_tracking<3>(lookup, seg.t0, seg.t1, seg.mu_bar.max(), rng, counters.tracking, T);
    }
    return !T.is_black();
  });
  return T;
}

bool transmittance_mis(const Scene& scene, const Ray& ray, double t_max, int light, int inside,
                       int hero, MisPath<3>& path, Rng& rng, Counters& counters) {
  ++counters.shadow_rays;
  if (occluded(scene, ray, t_max, light)) return false;
  auto lookup = [&](double t) { return as_sample(medium_at(scene, ray.at(t), inside)); };
  bool reaches = true;
  walk_majorant_segments(scene, ray, 0, t_max, inside, [&](const MajorantSegment& seg) {
    ++counters.majorant_segments;
    reaches = hero_ratio_tracking<3>(lookup, seg.t0, seg.t1, seg.mu_bar, hero, path, rng,
                                     counters.tracking);
    return reaches;
  });
  return reaches;
}

}  // namespace nimbus
