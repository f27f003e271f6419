#pragma once
// Figs. 1–3 of the paper: renders scenes/freeforms.json (Fig. 1, free forms), translucent.json
// (Fig. 2, subsurface scattering behind a dielectric boundary) and cloud.json (Fig. 3, a cloud
// with a functionally defined object inside) with the paper's method, spectral tracking under the
// history-aware rule, into fig<k>_<scene>.exr and .png; at the scenes' own size and sample count,
// or 48×32 at 1 sample per pixel when quick.
//
// Writes figures.csv: scene, size, samples, seconds and image mean per figure.

#include "nimbus/experiments/experiment.h"

namespace nimbus {

ExperimentReport run_figures(const ExperimentOptions& options);

}  // namespace nimbus
