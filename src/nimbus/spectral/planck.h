#pragma once
// Planck's law in absolute units, for media whose emission is a temperature (issue 14): a
// blackbody's spectral radiance at a wavelength, the same as a curve, and its linear sRGB from a
// table fast enough for a lookup per collision. The `{"blackbody": K}` colour
// (spectral_curve.h) is this curve normalised to a luminance; here brightness follows the
// temperature (roughly as T⁴ in the visible), as a fire's does.

#include "nimbus/spectral/spectral_curve.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

// The radiation constants for λ in nm: 2hc² in W·m⁻²·sr⁻¹·nm⁴ (so that B is per nm) and hc/k
// in nm·K (exact SI constants); and the root of x = 5 (1 − e^{−x}), which puts Wien's peak at
// λ = hc / (x k T).
inline constexpr double kPlanckC1 = 2 * 6.62607015e-34 * 299792458.0 * 299792458.0 * 1e36;
inline constexpr double kPlanckC2 = 6.62607015e-34 * 299792458.0 / 1.380649e-23 * 1e9;
inline constexpr double kWienX = 4.965114231744276303;

// Planck's spectral radiance B(λ, T) in W·m⁻²·sr⁻¹·nm⁻¹ at λ nm; 0 for λ <= 0 or T <= 0.
double planck_radiance(double lambda, double kelvin);

// B(·, T) as a curve: the blackbody shape of spectral_curve.h scaled to B at Wien's peak.
SpectralCurve planck_spectrum(double kelvin);

// The linear sRGB of B(·, T) as emitted radiance, emission_to_rgb(planck_spectrum(T)) with
// negative components (outside the gamut, below about 2 000 K) clamped to 0 as a blackbody
// colour's are, within a relative 1e-6 (tests/planck_test.cpp) for any T > 0; from a table
// over 1/T built once per process (about 0.1 s).
Rgb planck_rgb(double kelvin);

// The luminance of B(·, T) (that of planck_rgb before its clamp, in the units where RGB
// (1, 1, 1) has luminance 1), from the same table: what divides B to give the
// `{"blackbody": K}` colour of luminance 1. 0 for T <= 0.
double planck_luminance(double kelvin);

}  // namespace nimbus
