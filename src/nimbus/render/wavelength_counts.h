#pragma once
// The wavelengths per path that spectral mode is built for (CMake's NIMBUS_WAVELENGTH_COUNTS,
// by default 4, 8, 12 and 16): the render loop is compiled once per count, and scene files may
// ask for these only (docs/spectra.md).

#include <span>

#include "nimbus/render/counters.h"
#include "nimbus/render/film.h"
#include "nimbus/render/renderer.h"
#include "nimbus/render/scene.h"

namespace nimbus {

// In increasing order.
std::span<const int> built_wavelength_counts();

bool is_built_wavelength_count(int n);

// The render loop for spectral mode with n wavelengths, n one of built_wavelength_counts()
// (else std::invalid_argument).
RenderStats render_spectral(int n, const Scene& scene, Film& film, const RenderRange& range,
                            const RenderOptions& options, int threads);

}  // namespace nimbus
