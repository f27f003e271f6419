#pragma once
// Transmittance estimators along one segment [t0, t1] of a ray, for all N channels at once.
//
// Both sample tentative collisions t_i as a Poisson process of scalar rate mu_bar on [t0, t1]
// and multiply per-channel ratios. Their expectation is exactly T = exp(−∫ mu_t) for any
// mu_bar > 0 (the product over a Poisson process of (1 − f(t_i)/mu_bar) has expectation
// exp(−∫ f)), so they stay unbiased when mu_bar does not bound mu_t: the weight then just goes
// negative at some collisions. A bounding mu_bar keeps every factor in [0, 1]; one that fails is
// raised for the rest of the segment (raise_majorant).
//
// `lookup(t)` returns the MediumSample<N> at the point x(t) of the ray.

#include <algorithm>
#include <cmath>

#include "nimbus/math/rng.h"
#include "nimbus/spectral/spectrum.h"
#include "nimbus/tracking/counters.h"
#include "nimbus/tracking/free_flight.h"
#include "nimbus/tracking/medium_sample.h"

namespace nimbus {

// Below this, a transmittance estimate plays Russian roulette (transmittance_roulette).
inline constexpr double kRouletteThreshold = 0.1;

// The share of the contribution that a transmittance estimate T still carries: max|T| without a
// weight; with one (what multiplies T in the contribution: the path's throughput times the
// scattering function and the light, per channel) Σ|w T| / Σ|w|, so that a channel carrying
// little of the contribution cannot keep a walk going alone (issue 13).
template <int N>
double contribution_share(const Spectrum<N>& T, const Spectrum<N>* weight) {
  double m = T.max_abs();
  if (weight) {
    double wT = 0, w = 0;
    for (int c = 0; c < N; ++c) {
      wT += std::abs((*weight)[c] * T[c]);
      w += std::abs((*weight)[c]);
    }
    if (w > 0) m = wT / w;
  }
  return m;
}

// Russian roulette on a transmittance estimate T: once its share m of the contribution it can
// still make falls below kRouletteThreshold, T survives with probability q = m /
// kRouletteThreshold and is divided by q, else it becomes 0. E[T] is unchanged, and a shadow
// ray through a dense medium stops after a few more collisions instead of walking to its end.
// m is contribution_share(T, weight). Returns false when T was set to 0.
template <int N>
bool transmittance_roulette(Spectrum<N>& T, Rng& rng, const Spectrum<N>* weight = nullptr) {
  const double m = contribution_share(T, weight);
  if (m >= kRouletteThreshold) return true;
  const double q = m / kRouletteThreshold;
  if (rng.uniform() < q) {
    T /= q;
    return true;
  }
  T = Spectrum<N>(0.0);
  return false;
}

// Ratio tracking (Cramer 1978; Novák, Selle & Jarosz 2014): T ≈ Π_i (1 − mu_t(t_i)/mu_bar).
// mu_bar > 0; with mu_bar <= 0 no collision is sampled and T_in is returned, which is exact only
// where the segment is empty. T_in is the estimate over the ray's earlier segments: the result is
// T_in times this segment's, with Russian roulette on the running product (on its share of the
// contribution when `weight` is given: transmittance_roulette).
template <int N, class Lookup>
Spectrum<N> ratio_tracking(Lookup&& lookup, double t0, double t1, double mu_bar, Rng& rng,
                           TrackingCounters& counters, const Spectrum<N>& T_in = Spectrum<N>(1.0),
                           const Spectrum<N>* weight = nullptr) {
  Spectrum<N> T = T_in;
  track_tentative_collisions(lookup, t0, t1, mu_bar, rng, counters,
                             [&](double, const MediumSample<N>& m) {
                               const double needed = largest_carried(m.mu_t(), T);
                               T *= Spectrum<N>(1.0) - m.mu_t() / mu_bar;
                               raise_majorant(mu_bar, needed, counters);
                               return !T.is_black() && transmittance_roulette(T, rng, weight);
                             });
  return T;
}

// Residual ratio tracking (Novák, Selle & Jarosz 2014): with a control extinction mu_c, constant
// on the segment, T = exp(−mu_c (t1 − t0)) · E[Π_i (1 − (mu_t(t_i) − mu_c)/mu_bar_r)], the
// collisions sampled with rate mu_bar_r, a majorant of |mu_t − mu_c| over all channels. mu_c
// need not be a minorant. With mu_bar_r <= 0 (no residual) the control term alone is returned.
// T_in and the roulette as for ratio_tracking.
template <int N, class Lookup>
Spectrum<N> residual_ratio_tracking(Lookup&& lookup, double t0, double t1, const Spectrum<N>& mu_c,
                                    double mu_bar_r, Rng& rng, TrackingCounters& counters,
                                    const Spectrum<N>& T_in = Spectrum<N>(1.0),
                                    const Spectrum<N>* weight = nullptr) {
  Spectrum<N> T = T_in * exp(mu_c * (t0 - t1));
  track_tentative_collisions(lookup, t0, t1, mu_bar_r, rng, counters,
                             [&](double, const MediumSample<N>& m) {
                               const double needed = largest_carried(abs(m.mu_t() - mu_c), T);
                               T *= Spectrum<N>(1.0) - (m.mu_t() - mu_c) / mu_bar_r;
                               raise_majorant(mu_bar_r, needed, counters);
                               return !T.is_black() && transmittance_roulette(T, rng, weight);
                             });
  return T;
}

}  // namespace nimbus
