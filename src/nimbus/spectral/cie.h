#pragma once
// The CIE 1931 2° standard observer and the CIE D65 illuminant, tabulated every 5 nm over
// [360, 830] nm from Debian's colord-data files at build time (tools/gen_spectral_tables.cpp);
// linear interpolation between samples, 0 outside the table.

#include "nimbus/math/vec3.h"

namespace nimbus {

// (x̄, ȳ, z̄)(λ).
Vec3 cie_xyz_bar(double lambda);
// ∫ ȳ(λ) dλ over [360, 830] of the interpolated table: a spectrum s has luminance
// Y = ∫ s ȳ dλ / cie_y_integral(), so the constant spectrum 1 has Y = 1.
double cie_y_integral();
// The D65 spectral power distribution scaled so that its luminance (as above) is 1: an RGB
// white light (1, 1, 1) becomes this spectrum in spectral mode, and maps back to sRGB (1, 1, 1).
double d65_illuminant(double lambda);

}  // namespace nimbus
