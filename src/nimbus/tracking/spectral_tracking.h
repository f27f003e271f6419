#pragma once
// Spectral tracking (Kutz et al. 2017; paper §3): one free path for all channels along [t0, t1],
// tentative collisions at a scalar rate mu_bar (meant to be >= max_λ mu_t, but any mu_bar > 0 is
// unbiased, and where it fails it is raised for the rest of the segment: raise_majorant), an event
// at each drawn by `weighted_collision` under the caller's rule, until a real event (absorption or
// scattering) or the end of the segment.
//
// On return, w holds the path weight: for Escape, E[w] = w_in · exp(−∫_{t0}^{t1} mu_t) per channel;
// `emitted` has the weighted emission collected on the way added to it.

#include "nimbus/math/rng.h"
#include "nimbus/tracking/counters.h"
#include "nimbus/tracking/delta_tracking.h"
#include "nimbus/tracking/free_flight.h"
#include "nimbus/tracking/weighted_collision.h"

namespace nimbus {

template <int N, class Lookup>
Collision spectral_tracking(Lookup&& lookup, double t0, double t1, double mu_bar,
                            const EventPolicy& policy, Spectrum<N>& w, Spectrum<N>& emitted,
                            Rng& rng, TrackingCounters& counters) {
  Collision c{CollisionEvent::Escape, t1};
  track_tentative_collisions(
      lookup, t0, t1, mu_bar, rng, counters, [&](double t, const MediumSample<N>& m) {
        const double rate = mu_bar;  // the collision's; raised below for the next flights
        const Spectrum<N> mu_n = Spectrum<N>(rate) - m.mu_t();  // eq. 5
        // Raised at real events too: the caller learns from the count (volume.h).
        raise_majorant(mu_bar, largest_carried(m.mu_t(), w), counters);
        switch (weighted_collision(m, mu_n, rate, policy, w, emitted, rng.uniform())) {
          case TentativeEvent::Absorb:
            c = {CollisionEvent::Absorb, t};
            return false;
          case TentativeEvent::Scatter:
            c = {CollisionEvent::Scatter, t};
            return false;
          case TentativeEvent::Null:
            break;
        }
        return true;
      });
  return c;
}

}  // namespace nimbus
