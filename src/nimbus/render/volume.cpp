#include "nimbus/render/volume.h"

#include <algorithm>

#include "nimbus/tracking/delta_tracking.h"
#include "nimbus/tracking/transmittance.h"

namespace nimbus {
namespace {

MediumSample<3> as_sample(const MediumPoint& m) {
  MediumSample<3> s{m.mu_a, m.mu_s, Rgb(0.0)};
  for (int c = 0; c < 3; ++c) s.L_e[c] = m.mu_a[c] > 0 ? m.mu_a_Le[c] / m.mu_a[c] : 0.0;
  return s;
}

}  // namespace

MediumEvent sample_collision(const Scene& scene, const Ray& ray, double t_max, int inside,
                             int& channel, Rng& rng, Counters& counters) {
  MediumEvent ev;
  // The last lookup is the one at the collision that ends tracking: keep it.
  MediumPoint last;
  auto lookup = [&](double t) {
    last = medium_at(scene, ray.at(t), inside);
    return as_sample(last);
  };
  walk_majorant_segments(scene, ray, 0, t_max, inside, [&](const MajorantSegment& seg) {
    ++counters.majorant_segments;
    if (channel < 0) channel = std::min(2, static_cast<int>(rng.uniform() * 3));
    const Collision c = delta_tracking<3>(lookup, seg.t0, seg.t1, seg.mu_bar[channel], channel, rng,
                                          counters.tracking);
    if (c.event == CollisionEvent::Escape) return true;
    ++counters.real_collisions;
    ev.t = c.t;
    ev.medium = last;
    if (c.event == CollisionEvent::Scatter) {
      ++counters.scatter_events;
      ev.type = MediumEvent::Type::Scatter;
    } else {
      ev.type = MediumEvent::Type::Absorb;
      ev.emission = as_sample(last).L_e;
    }
    return false;
  });
  return ev;
}

Rgb transmittance(const Scene& scene, const Ray& ray, double t_max, int inside, Rng& rng,
                  Counters& counters) {
  ++counters.shadow_rays;
  if (occluded(scene, ray, t_max)) return Rgb(0.0);
  auto lookup = [&](double t) { return as_sample(medium_at(scene, ray.at(t), inside)); };
  Rgb T(1.0);
  walk_majorant_segments(scene, ray, 0, t_max, inside, [&](const MajorantSegment& seg) {
    ++counters.majorant_segments;
    T *= ratio_tracking<3>(lookup, seg.t0, seg.t1, seg.mu_bar.max(), rng, counters.tracking);
    return !T.is_black();
  });
  return T;
}

}  // namespace nimbus
