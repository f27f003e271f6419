#pragma once
// Free-flight sampling in a homogeneous (or majorant) medium of rate mu_bar, and the one loop
// over tentative collisions that every tracking estimator is built on.

#include <cmath>

#include "nimbus/math/rng.h"
#include "nimbus/tracking/counters.h"

namespace nimbus {

// A distance with density mu_bar exp(−mu_bar s), from u uniform in [0, 1), by inversion:
// s = −ln(1 − u) / mu_bar (log1p keeps small u accurate; u < 1 keeps s finite).
inline double free_flight(double mu_bar, double u) {
  return -std::log1p(-u) / mu_bar;
}

// Tentative collisions at rate mu_bar along [t0, t1], front to back: at each, the medium is
// looked up (and counted) and `at(t, lookup(t))` decides whether tracking goes on. Returns true
// when the segment's end was reached, false when `at` stopped it. mu_bar <= 0 samples none.
template <class Lookup, class AtCollision>
bool track_tentative_collisions(Lookup&& lookup, double t0, double t1, double mu_bar, Rng& rng,
                                TrackingCounters& counters, AtCollision&& at) {
  if (!(mu_bar > 0)) return true;
  for (double t = t0;;) {
    t += free_flight(mu_bar, rng.uniform());
    if (t >= t1) return true;
    ++counters.tentative_collisions;
    ++counters.lookups;
    if (!at(t, lookup(t))) return false;
  }
}

}  // namespace nimbus
