#pragma once
// Fig. 6 of the paper: the distribution of the distances between scattering events of spectral
// tracking under the max and the history-aware rule, in the homogeneous non-absorbing medium of
// Figs. 4–5 (sigma_s = (1, 5, 10), isotropic scattering, no absorption events), against the
// closed form sigma_s(λ) exp(−sigma_s(λ) t) that per-channel (delta) tracking samples.
//
// Writes scatter_distance.csv, one row per (rule, distance bin) with densities (per unit
// distance, so each integrates to the fraction of distances inside the histogram's range):
//   sampled_first    the first scattering distance, as sampled (unweighted)
//   sampled_between  every distance between successive scattering events, as sampled
//   weighted_<c>     the same distances weighted by channel c's throughput: Σ_k w_k 1[t_k ∈ bin]
//                    / Σ_k w_{k−1}. Each step of an unbiased tracker has E[w_k 1[t_k ∈ bin] | past]
//                    = w_{k−1} P_c(bin), so this ratio converges to the channel's exact density
//   analytic_<c>     the closed form, averaged over the bin

#include "nimbus/experiments/experiment.h"

namespace nimbus {

ExperimentReport run_scatter_distance(const ExperimentOptions& options);

}  // namespace nimbus
