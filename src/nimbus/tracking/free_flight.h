#pragma once
// Free-flight sampling in a homogeneous (or majorant) medium of rate mu_bar, and the one loop
// over tentative collisions that every tracking estimator is built on.

#include <algorithm>
#include <cmath>
#include <limits>

#include "nimbus/math/rng.h"
#include "nimbus/spectral/spectrum.h"
#include "nimbus/tracking/counters.h"

namespace nimbus {

// A distance with density mu_bar exp(−mu_bar s), from u uniform in [0, 1), by inversion:
// s = −ln(1 − u) / mu_bar (u < 1 keeps s finite). Every sampler's u is a multiple of 2⁻⁵³, for
// which 1 − u is exact, so log is as accurate as log1p here, and 2.6× faster (log1p was 8.6 % of
// a render of the grid cloud).
inline double free_flight(double mu_bar, double u) {
  return -std::log(1 - u) / mu_bar;
}

// Where a tentative collision finds mu_t above the rate the free flights are drawn with, the rest
// of the segment is tracked at kMajorantRaise times the value found (progressive null tracking,
// Misso et al. 2023). A rate that depends only on what the path has already seen keeps every
// null-collision estimator unbiased (the free flight from each collision is memoryless), and it
// stops the weights from growing at every later collision as they do under a fixed majorant
// that fails. The raise lasts for the segment only, so a sample's value depends on nothing but
// its own random numbers: images stay the same whatever the threads or processes.
inline constexpr double kMajorantRaise = 1.5;

// Raises mu_bar to kMajorantRaise · needed when needed, the coefficient the rate must bound at
// the collision just looked up, is above it; counted in counters.raised.
inline void raise_majorant(double& mu_bar, double needed, TrackingCounters& counters) {
  if (!(needed > mu_bar)) return;
  mu_bar = kMajorantRaise * needed;
  ++counters.raised;
}

// The largest x[c] over the channels c the weight w still carries: what a majorant must bound
// for the estimate that goes on (delta tracking carries one channel).
template <int N>
double largest_carried(const Spectrum<N>& x, const Spectrum<N>& w) {
  double m = -std::numeric_limits<double>::infinity();
  for (int c = 0; c < N; ++c)
    if (w[c] != 0) m = std::max(m, x[c]);
  return m;
}

// Tentative collisions at rate mu_bar along [t0, t1], front to back: at each, the medium is
// looked up (and counted) and `at(t, lookup(t))` decides whether tracking goes on. Returns true
// when the segment's end was reached, false when `at` stopped it. mu_bar <= 0 samples none.
// `at` may raise mu_bar (raise_majorant) once it has used the rate its collision was drawn with;
// the next free flight takes the new rate.
template <class Lookup, class AtCollision>
bool track_tentative_collisions(Lookup&& lookup, double t0, double t1, const double& mu_bar,
                                Rng& rng, TrackingCounters& counters, AtCollision&& at) {
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
