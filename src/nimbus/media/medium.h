#pragma once
// A participating medium at run time: coefficients per unit length, a phase function and a
// density (density.h). The medium at x is scale · density(x) · (sigma_a, sigma_s), emitting L_e:
// a constant, or blackbody radiance at a temperature grid (temperature_emission.h).

#include <array>
#include <memory>

#include "nimbus/media/constant_density.h"
#include "nimbus/media/density.h"
#include "nimbus/media/temperature_emission.h"
#include "nimbus/spectral/spectral_param.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

struct Medium {
  SpectralParam sigma_a, sigma_s;  // coefficients (role Unbounded)
  SpectralParam emission;          // L_e, entering the RTE as mu_a L_e (eq. 4) (role Illuminant)
  double g = 0;                    // Henyey–Greenstein asymmetry; 0 is isotropic
  DensityPtr density = make_constant_density();
  double scale = 1;  // multiplies the density
  // Set: L_e at each point is this grid's, and `emission` is 0.
  std::shared_ptr<const TemperatureEmission> emission_grid;
};

// A medium's coefficients at a path's N channels (spectral/channels.h), before the density.
template <int N>
struct MediumCoefficients {
  Spectrum<N> sigma_a, sigma_s, emission;
  // Set (a temperature grid): L_e varies and is evaluated per point at the channels below;
  // `emission` is then 0. Null for every medium of constant emission, which costs a test.
  const TemperatureEmission* emission_grid = nullptr;
  bool spectral = false;           // the channels are wavelengths
  std::array<double, N> lambda{};  // their wavelengths (nm), in spectral mode
};

}  // namespace nimbus
