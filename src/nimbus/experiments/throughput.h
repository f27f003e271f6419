#pragma once
// Figs. 4–5 of the paper: the R, G, B path throughput of spectral tracking against the distance
// travelled, under the max rule (eq. 6–9) and the history-aware average rule (eq. 10–13), in the
// unbounded non-absorbing media of chromatic_medium.h with sigma_s = (1, 5, 10): homogeneous, and
// heterogeneous with uncorrelated channels. Isotropic scattering, no absorption events (mu_a = 0).
//
// Writes throughput.csv, one row per (medium, rule, channel, distance) with the mean, standard
// deviation, 5/25/50/75/95 % quantiles, maximum and the fraction of exact zeros of the
// throughput over all walks. Channel "avg" is each walk's average over R, G, B: the history-aware
// rule keeps it at exactly 1 while mu_n >= 0 (Σ_λ w'(λ) = Σ_λ w(λ) after every event), the max rule
// does not.

#include "nimbus/experiments/experiment.h"

namespace nimbus {

ExperimentReport run_throughput(const ExperimentOptions& options);

}  // namespace nimbus
