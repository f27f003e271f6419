#pragma once
// The tables that tools/gen_spectral_tables.cpp writes at build time (into
// <build>/generated/nimbus/spectral_tables.cpp), and the conventions that the generator and the
// run-time code share: the 5 nm CIE grid, the 1 nm integration grid and the layout of the
// RGB-to-spectrum coefficient table (docs/spectra.md).

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>

#include "nimbus/spectral/wavelengths.h"

namespace nimbus::spectral_tables {

// CIE data every 5 nm over [kLambdaMin, kLambdaMax].
inline constexpr double kStep = 5;
inline constexpr int kBands = 95;
static_assert(kLambdaMin + (kBands - 1) * kStep == kLambdaMax);
extern const double kCmf[3][kBands];  // x̄, ȳ, z̄ (CIE 1931 2°)
extern const double kD65[kBands];     // CIE D65, relative as in the data file

// Linear interpolation in a 5 nm table of kBands values, 0 outside [kLambdaMin, kLambdaMax].
inline double interpolate(const double* v, double lambda) {
  if (!(lambda >= kLambdaMin && lambda <= kLambdaMax)) return 0;
  const double x = (lambda - kLambdaMin) / kStep;
  const int i = std::min(static_cast<int>(x), kBands - 2);
  const double f = x - i;
  return (1 - f) * v[i] + f * v[i + 1];
}

// Spectral integrals use the trapezoid rule on a 1 nm grid over [kLambdaMin, kLambdaMax]; its
// knots include the 5 nm ones, so integrals of the interpolated tables alone are exact.
inline constexpr int kGridPoints = 471;
static_assert(kLambdaMin + (kGridPoints - 1) == kLambdaMax);
constexpr double grid_lambda(int k) {
  return kLambdaMin + k;
}
constexpr double grid_weight(int k) {
  return k == 0 || k == kGridPoints - 1 ? 0.5 : 1.0;
}

// The RGB-to-spectrum table (after Jakob and Hanika 2019): for each choice of the largest
// component l of an RGB in [0, 1]³, a grid over z = rgb[l] (kZRes nodes) and
// x = rgb[(l + 1) % 3] / z, y = rgb[(l + 2) % 3] / z (kXyRes nodes each). Each entry holds the
// sigmoid's quadratic as (A, B, C) of A t² + B t + C in t = (λ − kMidNm) / kWidthNm ∈ [−½, ½]
// (well scaled for float storage and for the fit), as floats in the order l, z, y, x, coefficient.
inline constexpr int kZRes = 48, kXyRes = 48;
inline constexpr int kTableSize = 3 * kZRes * kXyRes * kXyRes * 3;
inline constexpr double kMidNm = 0.5 * (kLambdaMin + kLambdaMax),
                        kWidthNm = kLambdaMax - kLambdaMin;
// The floats' bit patterns: g++ compiles a million integer literals in less than half the time
// it takes for as many decimal floats.
extern const uint32_t kCoeffBits[kTableSize];

constexpr int table_index(int l, int z, int y, int x) {
  return (((l * kZRes + z) * kXyRes + y) * kXyRes + x) * 3;
}
inline float table_entry(int index) {
  return std::bit_cast<float>(kCoeffBits[index]);
}

// x and y nodes run from 0 to 1, denser near both ends where the coefficients change fastest.
// z nodes run from kZMin to 1, denser near 1: below kZMin, rgb_albedo_spectrum scales the curve
// at kZMin down instead, which keeps the relative error as small as at kZMin (a fit's
// coefficients diverge as z → 0, and interpolating them there loses tens of per cent).
constexpr double smoothstep(double t) {
  return t * t * (3 - 2 * t);
}
constexpr double xy_node(int i) {
  return smoothstep(i / double(kXyRes - 1));
}
inline constexpr double kZMin = 0.5;
constexpr double z_node(int k) {
  return kZMin + (1 - kZMin) * smoothstep(k / double(kZRes - 1));
}

// A t² + B t + C rewritten as c0 λ² + c1 λ + c2 with λ in nm.
constexpr std::array<double, 3> to_nm(double a, double b, double c) {
  constexpr double m = kMidNm, w = kWidthNm;
  return {a / (w * w), b / w - 2 * a * m / (w * w), a * m * m / (w * w) - b * m / w + c};
}

}  // namespace nimbus::spectral_tables
