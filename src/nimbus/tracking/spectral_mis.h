#pragma once
// Null-scattering spectral MIS (Miller, Georgiev & Jarosz 2019, §5–6), the form pbrt-v4's
// VolPathIntegrator uses. Free paths are sampled with one channel's majorant, the hero h, and the
// path carries, per channel λ, its throughput beta and two path pdfs rescaled by the hero's
// unidirectional pdf: r_u (the path as the unidirectional technique would sample it with λ as
// hero) and r_l (as light sampling would). A contribution f is then scored as
//   f / avg_λ p_λ = beta / avg(r_u)                  (one-sample MIS over the hero, balance)
//   f / avg_λ (p_u,λ + p_l,λ) = beta / avg(r_u + r_l) (with MIS against next-event estimation).
// Along a majorant segment of per-channel rates mu_maj, with T_maj = exp(−mu_maj Δt) since the
// last tentative collision (eq. numbers from Miller et al.):
//   scatter  pdf = T_maj[h] mu_s[h] b[h]:  beta *= T_maj mu_s / pdf,  r_u *= T_maj mu_s b / pdf
//   null     pdf = T_maj[h] |mu_n[h]| b[h]:  beta *= T_maj mu_n / pdf,
//            r_u *= T_maj |mu_n| b / pdf,  r_l *= T_maj mu_maj / pdf
//   escape   beta, r_u, r_l *= T_maj / T_maj[h]
//   emission scored at every tentative collision: beta T_maj/pdf mu_a L_e / avg(r_u mu_maj
//   T_maj/pdf)
//            with pdf = T_maj[h] mu_maj[h]
//   emission per unit length (render/glow.h) at a point u between tentative collisions, which
//   the path reaches with probability T_maj[h] over Δt = u − t_prev:
//            beta T_maj/T_maj[h] · len j / avg(r_u T_maj/T_maj[h])
// with b = 1 where the channel's majorant bounds mu_t and mu_maj / (mu_a + mu_s + |mu_n|) where
// it does not (failing_share). The hero's events are drawn with P_* = |mu_*[h]| b[h] / mu_maj[h]:
// where the majorant bounds, P_a = mu_a/mu_maj, P_s = mu_s/mu_maj, P_n = mu_n/mu_maj; where it
// does not (mu_n = mu_maj − mu_t < 0), the three in proportion to |mu_*|, as in the weighted
// trackers, so every channel's technique can still sample a null event and beta carries the
// signed mu_n: the estimate is unbiased for any positive majorants. A majorant that fails is
// raised for the rest of the segment (raise_majorants). Shadow rays are always unbiased: their
// light pdf r_l never vanishes.

#include <algorithm>
#include <cmath>

#include "nimbus/math/rng.h"
#include "nimbus/tracking/counters.h"
#include "nimbus/tracking/delta_tracking.h"
#include "nimbus/tracking/free_flight.h"
#include "nimbus/tracking/medium_sample.h"
#include "nimbus/tracking/transmittance.h"

namespace nimbus {

template <int N>
struct MisPath {
  Spectrum<N> beta{1.0}, r_u{1.0}, r_l{1.0};
};

// b per channel: 1 where the channel's majorant bounds mu_t; where it fails (mu_n < 0), the
// factor mu_maj / (mu_a + mu_s + |mu_n|) that turns P_* = mu_* b / mu_maj into probabilities
// proportional to |mu_*| that sum to 1, so the channel's technique still samples null events.
template <int N>
Spectrum<N> failing_share(const MediumSample<N>& m, const Spectrum<N>& mu_n,
                          const Spectrum<N>& mu_maj) {
  Spectrum<N> b(1.0);
  for (int i = 0; i < N; ++i)
    if (mu_n[i] < 0) b[i] = mu_maj[i] / (m.mu_a[i] + m.mu_s[i] - mu_n[i]);
  return b;
}

// Spectral MIS's majorants per channel, each raised where mu_t exceeds it (raise_majorant): every
// channel's technique raises at the same points, so the path pdfs stay those of the techniques.
template <int N>
void raise_majorants(Spectrum<N>& mu_maj, const Spectrum<N>& mu_t, TrackingCounters& counters) {
  bool raised = false;
  for (int c = 0; c < N; ++c)
    if (mu_t[c] > mu_maj[c]) {
      mu_maj[c] = kMajorantRaise * mu_t[c];
      raised = true;
    }
  counters.raised += raised;
}

// The free flight that passes the segment's end, over distance d: every path pdf is rescaled by
// the majorant transmittance relative to the hero channel's.
template <int N>
void rescale_to_segment_end(MisPath<N>& path, const Spectrum<N>& mu_maj, int h, double d) {
  const Spectrum<N> T_maj = exp(mu_maj * -d);
  path.beta *= T_maj / T_maj[h];
  path.r_u *= T_maj / T_maj[h];
  path.r_l *= T_maj / T_maj[h];
}

// No emission per unit length.
struct NoGlow {
  template <class F>
  void operator()(double, double, F&&) const {}
};

// Scores emission per unit length over (a, b) after the last tentative collision a, where the
// majorants are maj (render/glow.h gives the samples: glow(a, b, f) calls f(u, len j)).
template <int N, class Glow>
void score_glow(Glow& glow, double a, double b, const Spectrum<N>& maj, int h,
                const MisPath<N>& path, Spectrum<N>& emitted) {
  glow(a, b, [&](double u, const Spectrum<N>& len_j) {
    const Spectrum<N> T_maj = exp(maj * -(u - a));
    const Spectrum<N> ratio = T_maj / T_maj[h];
    const double r = (path.r_u * ratio).average();
    if (r > 0) emitted += path.beta * ratio * len_j / r;
  });
}

// Tracks [t0, t1] with hero channel h until a real collision or the segment's end; updates the
// path and adds the weighted emission to `emitted`, with that per unit length from `glow`.
template <int N, class Lookup, class Glow = NoGlow>
Collision hero_tracking(Lookup&& lookup, double t0, double t1, const Spectrum<N>& mu_maj, int h,
                        MisPath<N>& path, Spectrum<N>& emitted, Rng& rng,
                        TrackingCounters& counters, Glow&& glow = {}) {
  Collision c{CollisionEvent::Escape, t1};
  double t_prev = t0;        // the last tentative collision
  Spectrum<N> maj = mu_maj;  // raised where it fails (raise_majorants)
  const bool escaped = track_tentative_collisions(
      lookup, t0, t1, maj[h], rng, counters, [&](double t, const MediumSample<N>& m) {
        score_glow(glow, t_prev, t, maj, h, path, emitted);
        const double dt = t - t_prev;
        t_prev = t;
        const Spectrum<N> T_maj = exp(maj * -dt);
        const Spectrum<N> mu_a_Le = m.mu_a * m.L_e;
        if (!mu_a_Le.is_black()) {
          const double pdf = T_maj[h] * maj[h];
          const Spectrum<N> r_e = path.r_u * maj * T_maj / pdf;
          if (r_e.average() > 0) emitted += path.beta * T_maj / pdf * mu_a_Le / r_e.average();
        }
        const Spectrum<N> mu_t = m.mu_t();
        const Spectrum<N> mu_n = maj - mu_t;
        const Spectrum<N> drawn = maj;  // the collision's rates; raised for the next flights
        raise_majorants(maj, mu_t, counters);
        const Spectrum<N> b = failing_share(m, mu_n, drawn);
        const double P_a = m.mu_a[h] / drawn[h] * b[h];
        const double P_s = m.mu_s[h] / drawn[h] * b[h];
        const double u = rng.uniform();
        if (u < P_a) {
          path.beta = Spectrum<N>(0.0);
          c = {CollisionEvent::Absorb, t};
          return false;
        }
        if (u < P_a + P_s) {
          const double pdf = T_maj[h] * m.mu_s[h] * b[h];
          path.beta *= T_maj * m.mu_s / pdf;
          path.r_u *= T_maj * m.mu_s * b / pdf;
          c = {CollisionEvent::Scatter, t};
          return false;
        }
        const Spectrum<N> mu_n_abs = abs(mu_n);
        const double pdf = T_maj[h] * mu_n_abs[h] * b[h];
        if (pdf > 0) {
          path.beta *= T_maj * mu_n / pdf;
          path.r_u *= T_maj * mu_n_abs * b / pdf;
          path.r_l *= T_maj * drawn / pdf;
        }
        if (!(pdf > 0) || path.beta.is_black() || path.r_u.is_black()) {
          path.beta = Spectrum<N>(0.0);
          c = {CollisionEvent::Absorb, t};
          return false;
        }
        return true;
      });
  if (escaped) {
    score_glow(glow, t_prev, t1, maj, h, path, emitted);
    rescale_to_segment_end(path, maj, h, t1 - t_prev);
  }
  return c;
}

// Ratio tracking of a shadow segment for spectral MIS: T_ray (in `path.beta`) and the light and
// unidirectional pdfs rescaled by the hero's light-path pdf (pdf = T_maj[h] mu_maj[h] per
// tentative collision):  T_ray *= T_maj mu_n / pdf,  r_l *= T_maj mu_maj / pdf,
// r_u *= T_maj max(0, mu_n) / pdf, and at the end all three *= T_maj / T_maj[h]. The transmittance
// is T_ray / avg(r_u + r_l) once multiplied by the vertex pdfs. Russian roulette (q = 3/4) where
// |that estimate| falls below 0.05: its largest channel, or with a `weight` (what multiplies it
// in the contribution, per channel) its share Σ|w T| / Σ|w|, so that a channel carrying little
// of the contribution does not keep the walk going alone. Returns false once T_ray is 0.
template <int N, class Lookup>
bool hero_ratio_tracking(Lookup&& lookup, double t0, double t1, const Spectrum<N>& mu_maj, int h,
                         MisPath<N>& path, Rng& rng, TrackingCounters& counters,
                         const Spectrum<N>* weight = nullptr) {
  double t_prev = t0;        // the last tentative collision
  Spectrum<N> maj = mu_maj;  // raised where it fails (raise_majorants)
  const bool reached = track_tentative_collisions(
      lookup, t0, t1, maj[h], rng, counters, [&](double t, const MediumSample<N>& m) {
        const double dt = t - t_prev;
        t_prev = t;
        const Spectrum<N> T_maj = exp(maj * -dt);
        const Spectrum<N> mu_n = maj - m.mu_t();
        const double pdf = T_maj[h] * maj[h];
        path.beta *= T_maj * mu_n / pdf;
        path.r_l *= T_maj * maj / pdf;
        path.r_u *= T_maj * abs(mu_n) * failing_share(m, mu_n, maj) / pdf;
        const Spectrum<N> T = path.beta / (path.r_u + path.r_l).average();
        // |T|: a majorant that fails makes it signed.
        if (contribution_share(T, weight) < 0.05) {
          if (rng.uniform() < 0.75)
            path.beta = Spectrum<N>(0.0);
          else
            path.beta /= 0.25;
        }
        raise_majorants(maj, m.mu_t(), counters);
        return !path.beta.is_black();
      });
  if (reached) rescale_to_segment_end(path, maj, h, t1 - t_prev);
  return reached;
}

}  // namespace nimbus
