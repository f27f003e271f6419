#pragma once
// The paper's §4 claim that spectral tracking takes 20–25 % more path segments (tentative
// collisions) and density lookups than per-wavelength tracking, and what it buys in noise:
// scenes/cloud.json and scenes/translucent.json rendered with integrator.tracking = delta,
// spectral-max and spectral-history at the same size and sample count, each compared with one
// reference of the same scene at many more samples (delta tracking, another seed, so that its
// noise is independent of every compared image).
//
// Writes segments.csv, one row per (scene, tracking): counts per sample (one camera path per
// sample; segments and lookups include the ratio-tracked shadow rays), path segments per real
// scattering event (the inverse of the average step, in units of transport), their ratios to delta
// tracking, render seconds, the MSE against the reference, the
// reference's own variance (the film's estimate), the image's own variance estimate, and the
// time-normalised MSE, (MSE − reference variance) × seconds: lower is better at equal time.

#include "nimbus/experiments/experiment.h"

namespace nimbus {

ExperimentReport run_segments(const ExperimentOptions& options);

}  // namespace nimbus
