#pragma once
// Unbiased ray-marching transmittance (Kettunen, d'Eon, Pantaleoni & Novák 2021), over a whole
// ray at once, for all N channels.
//
// T = exp(−τ) with τ = ∫ mu_t. Each stretch carries a control mu_c (the octree's minorant), whose
// share of τ is known exactly, τ_c = ∫ mu_c; the residual τ_r = τ − τ_c is what is estimated:
//   - X, an unbiased estimate of τ_r, is one jittered ray march: M points, equally spaced in the
//     residual majorant's optical depth R = ∫ r (r = the largest tracked |mu_bar − mu_c|), so
//     points fall where the residual can be large and none where it is 0, each weighted by
//     (mu_t − mu_c)/r · R/M. E[X] = τ_r for any r > 0 wherever mu_t ≠ mu_c: r need not bound.
//   - The power series of exp about an independent march X_0 (the pivot):
//       exp(−τ_r) = exp(−X_0) Σ_k (X_0 − τ_r)^k / k!,
//     and with independent marches X_1, X_2, …, Π_{j<=k} (X_0 − X_j) has expectation
//     (X_0 − τ_r)^k given X_0. The series is cut by Russian roulette on its terms (the "aggressive"
//     roulette of the paper: every term is evaluated while it is large, then each further one
//     with a probability that shrinks with it), which keeps it unbiased.
// So T ≈ exp(−τ_c − X_0) Σ_k Π_{j<=k} (X_0 − X_j) / (j q_j), q_j the roulette's survival
// probabilities. Where the marches are accurate (smooth media, small steps) the terms vanish
// fast and the estimate is nearly exp(−τ); it may go negative, never unbounded.
//
// Cost: M = ceil(R / step) lookups per march, at least two marches (X_0, X_1); a thin ray
// (small R) takes one point per march. The ray is cut into chunks (ray_marching_transmittance),
// and before each chunk's series Russian roulette on the running estimate times exp(−τ_c − X_0)
// (transmittance_roulette, on the contribution when `weight` is given) stops rays that can carry
// little.

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "nimbus/math/rng.h"
#include "nimbus/spectral/spectrum.h"
#include "nimbus/tracking/counters.h"
#include "nimbus/tracking/medium_sample.h"
#include "nimbus/tracking/transmittance.h"

namespace nimbus {

// Series terms are all evaluated while their largest channel is above this; below it, the next
// one is evaluated with probability |term| / kSeriesRoulette.
inline constexpr double kSeriesRoulette = 0.1;

// The residual majorant's optical depth between two march points, and that of a chunk. On the
// dense chromatic bench cloud, steps and chunks of 1/4, 2/2, 4/4, 4/8, 8/8 and 16/16 gave
// efficiencies of 0.47, 0.60, 0.77, 0.72, 0.16 and 0.00 times delta tracking's (spectral-history;
// docs/benchmarks/shadow-ray-estimators.md): smaller steps cost lookups, larger ones make the
// marches so noisy that the series' terms grow.
struct MarchSettings {
  double step = 4;
  double chunk = 4;
};

// A stretch of the ray with its majorant and control extinction per channel.
template <int N>
struct MarchSegment {
  double t0, t1;
  Spectrum<N> mu_bar, mu_c;
};

namespace ray_marching_detail {

// The residual majorant r of a stretch: the largest tracked |mu_bar − mu_c|.
template <int N>
double residual_rate(const MarchSegment<N>& s, int channel) {
  const Spectrum<N> r = abs(s.mu_bar - s.mu_c);
  return channel < 0 ? r.max() : r[channel];
}

// One chunk: T times the chunk's transmittance estimate, R its residual majorant depth.
template <int N, class Lookup>
Spectrum<N> chunk_transmittance(Lookup& lookup, std::span<const MarchSegment<N>> segs, double R,
                                int channel, double step, Spectrum<N> T, Rng& rng,
                                TrackingCounters& counters, const Spectrum<N>* weight) {
  for (const MarchSegment<N>& s : segs) T *= exp(s.mu_c * (s.t0 - s.t1));
  if (!(R > 0)) return T;  // the control is exact
  const int M = static_cast<int>(std::ceil(R / step));
  const double du = R / M;
  // One jittered march: points at u_i = (i + jitter) du in the residual majorant's depth, mapped
  // to t stretch by stretch.
  auto march = [&]() {
    Spectrum<N> X(0.0);
    const double jitter = rng.uniform();
    int i = 0;
    double u_seg = 0;  // depth at the current stretch's start
    for (const MarchSegment<N>& s : segs) {
      const double r = residual_rate(s, channel);
      const double u_end = u_seg + r * (s.t1 - s.t0);
      for (; i < M; ++i) {
        const double u = (i + jitter) * du;
        if (u >= u_end) break;
        ++counters.lookups;
        const double t = std::min(s.t0 + (u - u_seg) / r, s.t1);
        X += (lookup(t).mu_t() - s.mu_c) * (du / r);
      }
      u_seg = u_end;
    }
    return X;
  };

  const Spectrum<N> X_0 = march();
  T *= exp(X_0 * -1.0);
  if (!transmittance_roulette(T, rng, weight)) return T;
  Spectrum<N> term(1.0), sum(1.0);
  for (int k = 1; k < 1000; ++k) {
    term *= (X_0 - march()) / k;
    sum += term;
    const double m = channel < 0 ? term.max_abs() : std::abs(term[channel]);
    if (!std::isfinite(m) || m == 0) break;
    if (m < kSeriesRoulette) {
      const double q = m / kSeriesRoulette;
      if (rng.uniform() >= q) break;
      term /= q;
    }
  }
  return T * sum;
}

}  // namespace ray_marching_detail

// T over the segments (sorted, disjoint; the ray has no medium between them), chunk by chunk
// front to back: each chunk holds settings.chunk of the residual majorant's depth (the last one
// less) and is estimated independently, so the product stays unbiased and Russian roulette
// between chunks ends a ray through a dense medium after a few chunks. channel >= 0: only that
// channel is estimated (the others come back 0). `weight` as for ratio_tracking.
template <int N, class Lookup>
Spectrum<N> ray_marching_transmittance(Lookup&& lookup, std::span<const MarchSegment<N>> segs,
                                       int channel, Rng& rng, TrackingCounters& counters,
                                       const Spectrum<N>* weight = nullptr,
                                       const MarchSettings& settings = {}) {
  Spectrum<N> T(channel < 0 ? 1.0 : 0.0);
  if (channel >= 0) T[channel] = 1;
  thread_local std::vector<MarchSegment<N>> chunk;
  chunk.clear();
  double R = 0;  // the chunk's residual majorant depth so far
  auto flush = [&]() {
    T = ray_marching_detail::chunk_transmittance<N>(lookup, std::span<const MarchSegment<N>>(chunk),
                                                    R, channel, settings.step, T, rng, counters,
                                                    weight);
    chunk.clear();
    R = 0;
    return !T.is_black();
  };
  for (MarchSegment<N> s : segs) {
    const double r = ray_marching_detail::residual_rate(s, channel);
    // Cut the stretch where the chunk is full.
    while (r > 0 && R + r * (s.t1 - s.t0) > settings.chunk) {
      const double t = s.t0 + (settings.chunk - R) / r;
      chunk.push_back({s.t0, t, s.mu_bar, s.mu_c});
      R = settings.chunk;
      if (!flush()) return T;
      s.t0 = t;
    }
    chunk.push_back(s);
    R += r * (s.t1 - s.t0);
  }
  flush();
  return T;
}

}  // namespace nimbus
