#pragma once
// A random walk through an unbounded ChromaticMedium with spectral tracking (paper §3): free paths
// at the rate majorant(m), an event at every tentative collision under `policy`, and a new
// direction from the Henyey–Greenstein phase function with parameter g at every scattering event.
// The walk starts at the origin with weight 1 and never leaves the medium, so it only ends when
// the observer says so or when every channel's weight is 0.
//
// The distance travelled (the path length, summed over segments) is cut at the multiples of
// `edge_spacing`; the free flight is memoryless, so restarting the tracker at a cut does not change
// the walk's distribution. The observer is told
//   bool edge(const Rgb& w)               the weight on reaching each multiple, in turn
//   bool scatter(double d, const Rgb& w)  the distance travelled and the weight after each
//   scattering
// and either returns false to end the walk. When all weights reach 0 the walk ends silently.

#include <limits>

#include "nimbus/experiments/chromatic_medium.h"
#include "nimbus/math/rng.h"
#include "nimbus/media/phase.h"
#include "nimbus/tracking/spectral_tracking.h"

namespace nimbus {

template <class Observer>
void infinite_walk(const ChromaticMedium& m, const EventPolicy& policy, double g,
                   double edge_spacing, Rng& rng, TrackingCounters& counters, Observer& observer) {
  const double mu_bar = majorant(m);
  Vec3 x{0, 0, 0}, dir{0, 0, 1};
  Rgb w(1.0), emitted(0.0);
  double d = 0;
  for (int edge = 1;;) {
    const double next_edge = edge_spacing * edge;
    const auto lookup = [&](double t) { return medium_at(m, x + t * dir); };
    const Collision c =
        spectral_tracking<3>(lookup, 0, next_edge - d, mu_bar, policy, w, emitted, rng, counters);
    x += c.t * dir;
    switch (c.event) {
      case CollisionEvent::Escape:
        d = next_edge;
        ++edge;
        if (!observer.edge(w)) return;
        break;
      case CollisionEvent::Scatter:
        d += c.t;
        if (!observer.scatter(d, w)) return;
        dir = sample_hg(dir, g, rng.uniform(), rng.uniform());
        break;
      case CollisionEvent::Absorb:  // no absorption here: only when every weight is 0
        return;
    }
  }
}

// An edge spacing that never cuts the walk.
inline constexpr double kNoEdges = std::numeric_limits<double>::infinity();

}  // namespace nimbus
