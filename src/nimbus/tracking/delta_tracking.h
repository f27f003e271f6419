#pragma once
// Delta tracking (Woodcock et al. 1965) for one channel: samples the first real collision along
// [t0, t1] and its kind, using a scalar majorant mu_bar.
//
// Tentative collisions come at rate mu_bar. At each, with the chosen channel c, absorption has
// probability P_a = mu_a[c]/mu_bar, scattering P_s = mu_s[c]/mu_bar, and the null event the
// rest, P_n = 1 − P_a − P_s = mu_n/mu_bar. The collision density is then exactly
// mu_t(t) exp(−∫_{t0}^t mu_t) and the escape probability exp(−∫_{t0}^{t1} mu_t), provided mu_bar
// bounds mu_t[c]. Where it does not (mu_n < 0), this estimator cannot represent the negative
// null probability: it clamps (P_a, P_s) to (mu_a, mu_s)/mu_t, counts the point in
// `counters.clamped`, and is biased there (free paths too long); the rest of the segment is then
// tracked with a raised majorant (raise_majorant), so the bias stays at that one collision. Use
// it with bounding majorants; the counts say when that was violated.

#include "nimbus/math/rng.h"
#include "nimbus/tracking/counters.h"
#include "nimbus/tracking/free_flight.h"
#include "nimbus/tracking/medium_sample.h"

namespace nimbus {

enum class CollisionEvent { Scatter, Absorb, Escape };

struct Collision {
  CollisionEvent event;
  double t;  // the collision's ray parameter; t1 on escape
};

// mu_bar > 0 (mu_bar <= 0 samples no collision and escapes). 0 <= channel < N.
template <int N, class Lookup>
Collision delta_tracking(Lookup&& lookup, double t0, double t1, double mu_bar, int channel,
                         Rng& rng, TrackingCounters& counters) {
  Collision c{CollisionEvent::Escape, t1};
  track_tentative_collisions(lookup, t0, t1, mu_bar, rng, counters,
                             [&](double t, const MediumSample<N>& m) {
                               const double mu_a = m.mu_a[channel], mu_s = m.mu_s[channel];
                               double P_a = mu_a / mu_bar, P_s = mu_s / mu_bar;
                               if (P_a + P_s > 1) {
                                 ++counters.clamped;
                                 P_a = mu_a / (mu_a + mu_s);
                                 P_s = 1 - P_a;
                               }
                               const double u = rng.uniform();
                               if (u < P_a)
                                 c = {CollisionEvent::Absorb, t};
                               else if (u < P_a + P_s)
                                 c = {CollisionEvent::Scatter, t};
                               raise_majorant(mu_bar, mu_a + mu_s, counters);
                               return c.event == CollisionEvent::Escape;
                             });
  return c;
}

}  // namespace nimbus
