#pragma once
// One tentative collision of a weighted (spectral) tracker (Kutz et al. 2017; paper §3): the
// event — absorption, scattering or null — is drawn with probabilities P_a, P_s, P_n of the
// caller's choosing, and the weight of every channel λ is multiplied by mu_*(x,λ)/(mu_bar P_*)
// for the chosen event *. Any probabilities that are positive wherever mu_*(x,λ) w(λ) != 0 keep
// E[w] exact, which is why the rules take absolute values: they stay unbiased when mu_bar does
// not bound mu_t (mu_n < 0; the weight then changes sign).
//
// Rules (paper eq. 6–13), each normalised by c, the sum of the three terms:
//   Channel  P_* = |mu_*(x,λ_c)| / c              one channel (delta tracking with weights)
//   Max      P_* = max_λ |mu_*(x,λ)| / c          eq. 6–9
//   History  P_* = avg_λ |mu_*(x,λ) w(λ)| / c     eq. 10–13, w the path throughput so far
//
// Without absorption events (paper step 8), P_a = 0 and the source term of the RTE is collected
// by its collision estimate at every tentative collision instead: with free flights of density
// mu_bar exp(−mu_bar t), the integral form L = ∫ T̄ (mu_a L_e + mu_s L_s + mu_n L) dt
// (docs/design.md, "Radiative transfer with null collisions") is estimated by
// w mu_a L_e / mu_bar + w mu_*/(mu_bar P_*) L_* for the sampled * ∈ {s, n}.
// With absorption events, the emission is collected once, at an absorption: w mu_a/(mu_bar P_a)
// L_e.

#include <algorithm>
#include <cmath>

#include "nimbus/spectral/spectrum.h"
#include "nimbus/tracking/medium_sample.h"

namespace nimbus {

enum class EventRule { Channel, Max, History };

struct EventPolicy {
  EventRule rule = EventRule::Max;
  int channel = 0;                // Channel rule: the tracked channel
  bool absorption_events = true;  // false: P_a = 0, absorption acts through the weights
};

enum class TentativeEvent { Absorb, Scatter, Null };

// The event at one tentative collision with coefficients m and null coefficient mu_n, sampled at
// rate mu_bar > 0, from u uniform in [0, 1). Updates the weight w and adds the emitted radiance
// (already weighted) to `emitted`. When every event carries zero weight (c = 0) the path can
// contribute nothing more: w becomes 0 and Absorb is returned.
template <int N>
TentativeEvent weighted_collision(const MediumSample<N>& m, const Spectrum<N>& mu_n, double mu_bar,
                                  const EventPolicy& policy, Spectrum<N>& w, Spectrum<N>& emitted,
                                  double u) {
  double a = 0, s = 0, n = 0;
  switch (policy.rule) {
    case EventRule::Channel:
      a = std::abs(m.mu_a[policy.channel]);
      s = std::abs(m.mu_s[policy.channel]);
      n = std::abs(mu_n[policy.channel]);
      break;
    case EventRule::Max:
      for (int i = 0; i < N; ++i) {
        a = std::max(a, std::abs(m.mu_a[i]));
        s = std::max(s, std::abs(m.mu_s[i]));
        n = std::max(n, std::abs(mu_n[i]));
      }
      break;
    case EventRule::History:  // averages up to the common factor 1/N, which c cancels
      for (int i = 0; i < N; ++i) {
        a += std::abs(m.mu_a[i] * w[i]);
        s += std::abs(m.mu_s[i] * w[i]);
        n += std::abs(mu_n[i] * w[i]);
      }
      break;
  }
  if (!policy.absorption_events) {
    emitted += w * m.mu_a * m.L_e / mu_bar;
    a = 0;
  }
  const double c = a + s + n;
  if (!(c > 0)) {
    w = Spectrum<N>(0.0);
    return TentativeEvent::Absorb;
  }
  // P_* = x/c, so mu_*/(mu_bar P_*) = mu_* c / (mu_bar x). An event of probability 0 is never
  // taken: u·c rounds up to c when c is subnormal, which would pick a null event with n = 0.
  const double uc = u * c;
  if (uc >= a + s && n > 0) {
    w *= mu_n * (c / (mu_bar * n));
    return TentativeEvent::Null;
  }
  if (uc < a || !(s > 0)) {
    w *= m.mu_a * (c / (mu_bar * a));
    emitted += w * m.L_e;
    return TentativeEvent::Absorb;
  }
  w *= m.mu_s * (c / (mu_bar * s));
  return TentativeEvent::Scatter;
}

}  // namespace nimbus
