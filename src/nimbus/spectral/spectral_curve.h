#pragma once
// A spectral distribution that a scene defines: a value per wavelength (nm). RGB inputs become
// smooth curves here (docs/spectra.md): a reflectance-like RGB in [0, 1] becomes a sigmoid of a
// quadratic, s(λ) = S(c0 λ² + c1 λ + c2) with S(x) = 1/2 + x / (2 √(1 + x²)), bounded in [0, 1]
// (Jakob and Hanika 2019), its coefficients interpolated from a table generated at build time
// and polished by Gauss–Newton;
// unbounded RGB (coefficients, radiance) is a scale times such a curve; illuminants are further
// multiplied by D65 so that an RGB white light renders white.

#include <utility>
#include <vector>

#include "nimbus/math/vec3.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

struct SpectralCurve {
  enum class Type { Constant, Sigmoid, PiecewiseLinear, Blackbody };
  Type type = Type::Constant;
  double scale = 1;                               // multiplies the shape below
  double c0 = 0, c1 = 0, c2 = 0;                  // Sigmoid: the quadratic in λ (nm)
  std::vector<std::pair<double, double>> points;  // PiecewiseLinear: (nm, value), increasing nm
  double kelvin = 0;                              // Blackbody: temperature
  bool illuminant = false;                        // times d65_illuminant(λ)

  // The value at λ. PiecewiseLinear holds its end values beyond its first and last points; the
  // Blackbody shape is Planck's law divided by its value at Wien's peak.
  double operator()(double lambda) const;
  // Exact lower and upper bounds of the value over [lo, hi] nm (for majorants). With
  // `illuminant`, the product of the curve's and D65's exact bounds: safe, possibly loose.
  std::pair<double, double> range(double lo, double hi) const;
};

SpectralCurve constant_spectrum(double value);
// rgb in [0, 1]³: a curve in [0, 1] whose reflectance_to_rgb is rgb to ~1e-13, except grey
// (r = g = b), which gives the constant exactly (projecting to D65's white, off by 4e-4).
// Components are clamped into [0, 1]; a largest component below 1/2 gives the curve at 1/2 scaled
// down (docs/spectra.md).
SpectralCurve rgb_albedo_spectrum(const Rgb& rgb);
// rgb >= 0: scale 2·max(rgb) times the albedo curve of rgb / scale. Grey gives the constant.
SpectralCurve rgb_unbounded_spectrum(const Rgb& rgb);
// rgb >= 0: the unbounded curve times D65, so that emission_to_rgb returns rgb.
SpectralCurve rgb_illuminant_spectrum(const Rgb& rgb);
// (nm, value) points with strictly increasing nm, at least one.
SpectralCurve piecewise_linear_spectrum(std::vector<std::pair<double, double>> points);
// Planck's law at `kelvin`, normalised to luminance `scale` (the luminance of RGB (s, s, s)).
SpectralCurve blackbody_spectrum(double kelvin, double scale);

// XYZ of a spectrum seen as emitted radiance: ∫ s (x̄, ȳ, z̄) dλ / cie_y_integral().
Vec3 emission_to_xyz(const SpectralCurve& s);
// Linear sRGB of emitted radiance: xyz_to_linear_srgb(emission_to_xyz(s)).
Rgb emission_to_rgb(const SpectralCurve& s);
// Linear sRGB of a reflectance (or any coefficient) under the D65 illuminant:
// xyz_to_linear_srgb(∫ s D65 (x̄, ȳ, z̄) dλ / ∫ D65 ȳ dλ).
Rgb reflectance_to_rgb(const SpectralCurve& s);

}  // namespace nimbus
