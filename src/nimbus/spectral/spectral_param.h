#pragma once
// A colour input of the scene as the renderer keeps it: the RGB value that rgb mode renders with,
// and the curve that spectral mode samples. A curve the scene file gave (sampled points, a
// blackbody) comes with its RGB projection; an RGB input gets its curve by upsampling, how
// depending on what the value means (its role).

#include <optional>
#include <vector>

#include "nimbus/spectral/spectral_curve.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

enum class SpectralRole {
  Albedo,      // in [0, 1]: the bounded upsampling
  Unbounded,   // a coefficient (>= 0): scale times a bounded curve
  Illuminant,  // emitted radiance (>= 0): unbounded times D65
};

struct SpectralParam {
  Rgb rgb{0.0};
  std::optional<SpectralCurve> curve;  // absent: upsample rgb (complete_spectrum)
  // The curve's upper bound over each wavelength bin of the majorant octree (channels.h), as the
  // octree takes it (SpectralCurve::range); empty where not known. complete_spectrum and
  // from_curve fill it: a path then scales its bin's majorant to its own wavelength.
  std::vector<double> bin_max;

  SpectralParam() = default;
  SpectralParam(const Rgb& value) : rgb(value) {}  // NOLINT: scenes built in code give RGB
};

// The largest value p takes: of its RGB channels and, once complete_spectrum has filled them, of
// its spectral bins' bounds.
inline double largest_value(const SpectralParam& p) {
  double m = p.rgb.max();
  for (double b : p.bin_max) m = m > b ? m : b;
  return m;
}

// Gives p its curve from its RGB if it has none, and fills its bin_max from its curve.
void complete_spectrum(SpectralParam& p, SpectralRole role);

// A curve given in the scene file, with the RGB that rgb mode uses for it: its reflectance
// projection (albedo and coefficients, clamped to [0, 1] or >= 0) or its emission projection.
SpectralParam from_curve(SpectralCurve curve, SpectralRole role);

}  // namespace nimbus
