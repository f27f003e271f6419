#pragma once
// Decomposition tracking (Kutz et al. 2017, §5; paper steps 2 and 6) with spectral weights.
//
// The extinction is split into an achromatic control part mu_c, constant on [t0, t1], and a
// residual: mu_t(x,λ) = mu_c + mu_r(x,λ). The control part is divided between absorption and
// scattering in the local ratio, mu_c,a = mu_c mu_a/mu_t and mu_c,s = mu_c mu_s/mu_t (all
// absorption where mu_t = 0), and the residual takes the rest, mu_r,* = mu_* − mu_c,*. The
// tentative collisions of the two parts are independent Poisson processes of rates mu_c and
// mu_bar_r = mu_bar − mu_c, and their union is the process of rate mu_bar, so the nearer of
//   - the control collision, sampled once in closed form, t_c = t0 − ln(1 − u)/mu_c, and
//   - the next tentative collision of the residual, tracked by `spectral_tracking`
// is the next tentative collision. Residual collisions up to t_c are handled as in spectral
// tracking with coefficients mu_r and null mu_bar_r − mu_r = mu_bar − mu_t; reaching t_c is a
// real collision of the control part (it has no null part): absorption or scattering with the
// rule's probabilities, weights mu_c,*(λ)/(mu_c P_*). Without absorption events it always
// scatters and the weight is multiplied by the local albedo mu_s/mu_t per channel. Density
// lookups happen only at residual collisions and at the control collision itself (where the
// caller needs the point's phase function anyway).
//
// With mu_c = 0 this is spectral tracking exactly; with mu_c = mu_bar there is no residual to
// track. Where mu_bar − mu_c < 0 (a majorant scaled below the control), the residual is tracked
// at rate mu_bar instead: any positive rate is unbiased with the weighted events.

#include <algorithm>
#include <limits>

#include "nimbus/tracking/spectral_tracking.h"

namespace nimbus {

// The control part of the coefficients at a point: mu_c split in the local ratio mu_a : mu_s.
template <int N>
MediumSample<N> control_part(const MediumSample<N>& m, double mu_c) {
  MediumSample<N> c{Spectrum<N>(0.0), Spectrum<N>(0.0), m.L_e};
  for (int i = 0; i < N; ++i) {
    const double mu_t = m.mu_a[i] + m.mu_s[i];
    c.mu_a[i] = mu_t > 0 ? mu_c * m.mu_a[i] / mu_t : mu_c;
    c.mu_s[i] = mu_t > 0 ? mu_c * m.mu_s[i] / mu_t : 0.0;
  }
  return c;
}

template <int N, class Lookup>
Collision decomposition_tracking(Lookup&& lookup, double t0, double t1, double mu_c, double mu_bar,
                                 const EventPolicy& policy, Spectrum<N>& w, Spectrum<N>& emitted,
                                 Rng& rng, TrackingCounters& counters) {
  const double t_c =
      mu_c > 0 ? t0 + free_flight(mu_c, rng.uniform()) : std::numeric_limits<double>::infinity();
  auto residual = [&](double t) {
    const MediumSample<N> m = lookup(t);
    const MediumSample<N> c = control_part(m, mu_c);
    return MediumSample<N>{m.mu_a - c.mu_a, m.mu_s - c.mu_s, m.L_e};
  };
  const double mu_bar_r = mu_bar - mu_c >= 0 ? mu_bar - mu_c : mu_bar;
  const Collision r = spectral_tracking<N>(residual, t0, std::min(t_c, t1), mu_bar_r, policy, w,
                                           emitted, rng, counters);
  if (r.event != CollisionEvent::Escape) return r;
  if (t_c >= t1) return {CollisionEvent::Escape, t1};
  ++counters.tentative_collisions;
  ++counters.lookups;
  const MediumSample<N> c = control_part(lookup(t_c), mu_c);
  const TentativeEvent e =
      weighted_collision(c, Spectrum<N>(0.0), mu_c, policy, w, emitted, rng.uniform());
  // P_n = 0 here, so the event is real.
  return {e == TentativeEvent::Scatter ? CollisionEvent::Scatter : CollisionEvent::Absorb, t_c};
}

}  // namespace nimbus
