#pragma once
// When a render test of a weighted tracker can hold: the criterion by which render tests skip a
// tracking mode (issue 17), computed instead of observed.
//
// A tracker whose event probabilities are fixed by the point (the channel rule of delta tracking
// and the max rule, eq. 6–9) multiplies a channel's weight at each tentative collision by
// f_* = mu_*(λ) / (mu_bar P_*) for the event * it draws. The second moment of the weight that
// goes on (scatter or null; absorption ends the path) grows per tentative collision by
//   rho(λ) = Σ_{* ∈ {s, n}} P_* f_*² = (c / mu_bar²) Σ_* mu_*(λ)² / x_*,
// with x_* the rule's unnormalised probabilities and c their sum (paper eq. 6–9). With
// decomposition the tentative collisions are the residual's (rate mu_bar − mu_c, coefficients
// mu_* − mu_c mu_*/mu_t, the same null) or the control's (rate mu_c, no null), in proportion to
// their rates. If rho <= 1 at every point the weights' second moment stays bounded, and with
// paths that end (escape, absorption) the variance is finite. If rho > 1 somewhere, the k-th
// scattering order can carry second moment growing like rho^k: in a medium where paths scatter
// without bound the variance may be infinite, no standard error means anything, and the test is
// skipped. The history rule (eq. 10–13) and spectral MIS adapt their probabilities to the
// weights and have no such closed form.

#include <algorithm>
#include <cmath>
#include <vector>

#include "nimbus/spectral/spectrum.h"
#include "nimbus/tracking/weighted_collision.h"

namespace nimbus::test {

// Coefficients per channel: rgb channels, or a spectrum at many wavelengths.
using Channels = std::vector<double>;

// rho per tracked channel, max over them, for one process: coefficients a, s (per channel) and
// null n, sampled at rate R. `channel` >= 0: the channel rule on that channel (only its weight
// is carried); -1: the max rule over all channels.
inline double process_growth(const Channels& a, const Channels& s, const Channels& n, double R,
                             int channel, bool absorption_events) {
  const int N = static_cast<int>(a.size());
  double x_a = 0, x_s = 0, x_n = 0;
  for (int i = 0; i < N; ++i) {
    if (channel >= 0 && i != channel) continue;
    x_a = std::max(x_a, std::abs(a[i]));
    x_s = std::max(x_s, std::abs(s[i]));
    x_n = std::max(x_n, std::abs(n[i]));
  }
  const double c = (absorption_events ? x_a : 0.0) + x_s + x_n;
  double rho = 0;
  for (int i = 0; i < N; ++i) {
    if (channel >= 0 && i != channel) continue;
    double r = 0;
    if (x_s > 0) r += s[i] * s[i] / x_s;
    if (x_n > 0) r += n[i] * n[i] / x_n;
    rho = std::max(rho, c / (R * R) * r);
  }
  return rho;
}

// rho at a point with coefficients mu_a, mu_s, majorant mu_bar and control mu_c (0 without
// decomposition), as decomposition_tracking splits them.
inline double point_growth(const Channels& mu_a, const Channels& mu_s, double mu_bar, double mu_c,
                           int channel, bool absorption_events) {
  const size_t N = mu_a.size();
  const double R = mu_bar - mu_c >= 0 ? mu_bar - mu_c : mu_bar;
  Channels ca(N), cs(N), ra(N), rs(N), n(N);
  for (size_t i = 0; i < N; ++i) {
    const double mu_t = mu_a[i] + mu_s[i];
    ca[i] = mu_t > 0 ? mu_c * mu_a[i] / mu_t : mu_c;
    cs[i] = mu_t > 0 ? mu_c * mu_s[i] / mu_t : 0.0;
    ra[i] = mu_a[i] - ca[i];
    rs[i] = mu_s[i] - cs[i];
    n[i] = R - (mu_t - mu_c);
  }
  double rho =
      R > 0 ? R / (R + mu_c) * process_growth(ra, rs, n, R, channel, absorption_events) : 0.0;
  if (mu_c > 0)
    rho += mu_c / (R + mu_c) *
           process_growth(ca, cs, Channels(N, 0.0), mu_c, channel, absorption_events);
  return rho;
}

// The largest rho of a medium sigma_a, sigma_s (per channel) times a density, over densities
// d in (0, 1] of the majorant's (d = 1 only if `homogeneous`), over controls from 0 to the
// largest the octree can give there (d min_λ sigma_t), and over the tracked channels, with the
// majorant `scale` times the bound: the max over channels for the max rule, the tracked
// channel's own for the channel rule (delta tracking).
inline double medium_growth(EventRule rule, const Channels& sigma_a, const Channels& sigma_s,
                            bool homogeneous, double scale, bool decomposition,
                            bool absorption_events) {
  const size_t N = sigma_a.size();
  Channels sigma_t(N);
  for (size_t i = 0; i < N; ++i) sigma_t[i] = sigma_a[i] + sigma_s[i];
  const double t_min = *std::min_element(sigma_t.begin(), sigma_t.end());
  const double t_max = *std::max_element(sigma_t.begin(), sigma_t.end());
  double rho = 0;
  const int steps = homogeneous ? 1 : 200, controls = decomposition ? 20 : 0;
  for (int k = 1; k <= steps; ++k) {
    const double d = double(k) / steps;
    Channels a(N), s(N);
    for (size_t i = 0; i < N; ++i) {
      a[i] = d * sigma_a[i];
      s[i] = d * sigma_s[i];
    }
    for (int j = 0; j <= controls; ++j) {
      const double mu_c = d * t_min * j / std::max(controls, 1);
      if (rule == EventRule::Max) {
        rho = std::max(rho, point_growth(a, s, scale * t_max, mu_c, -1, absorption_events));
        continue;
      }
      for (size_t ch = 0; ch < N; ++ch)
        rho = std::max(rho, point_growth(a, s, scale * sigma_t[ch], mu_c, static_cast<int>(ch),
                                         absorption_events));
    }
  }
  return rho;
}

inline Channels channels(const Rgb& x) {
  return {x[0], x[1], x[2]};
}

}  // namespace nimbus::test
