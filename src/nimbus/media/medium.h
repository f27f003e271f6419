#pragma once
// A participating medium at run time: coefficients per unit length, a phase function and a
// density (density.h). The medium at x is scale · density(x) · (sigma_a, sigma_s), emitting L_e:
// a constant, or blackbody radiance at a temperature grid (temperature_emission.h). It may also
// emit j per unit length wherever its object holds it, whatever mu_a and the density (Cycles'
// volume emission; render/glow.h).

#include <array>
#include <memory>

#include "nimbus/media/constant_density.h"
#include "nimbus/media/density.h"
#include "nimbus/media/temperature_emission.h"
#include "nimbus/media/texture.h"
#include "nimbus/spectral/spectral_param.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

struct Medium {
  SpectralParam sigma_a, sigma_s;  // coefficients (role Unbounded)
  // Solid textures (media/texture.h): set, sigma_a (sigma_s) is the coefficient where t = 0 and
  // sigma_a_to (sigma_s_to) where t = 1, before the density.
  Texture sigma_a_texture, sigma_s_texture;
  SpectralParam sigma_a_to, sigma_s_to;
  SpectralParam emission;  // L_e, entering the RTE as mu_a L_e (eq. 4) (role Illuminant)
  double g = 0;            // Henyey–Greenstein asymmetry; 0 is isotropic
  DensityPtr density = make_constant_density();
  double scale = 1;  // multiplies the density
  // Set: L_e at each point is this grid's, and `emission` is 0.
  std::shared_ptr<const TemperatureEmission> emission_grid;
  // Radiance emitted per unit length, independent of sigma_a and the density: a constant, or
  // this grid's L_e where it is set (`j` is then 0) (role Illuminant).
  SpectralParam j;
  std::shared_ptr<const TemperatureEmission> j_grid;
};

// Whether the medium emits per unit length (render/glow.h).
inline bool glows(const Medium& m) {
  return m.j_grid || largest_value(m.j) > 0;
}

// Whether the medium's density or textures read F, the holding object's function at the point.
inline bool medium_uses_F(const Medium& m) {
  return m.density->uses_F() || (m.sigma_a_texture && m.sigma_a_texture.pattern->uses_F()) ||
         (m.sigma_s_texture && m.sigma_s_texture.pattern->uses_F());
}

// A medium's coefficients at a path's N channels (spectral/channels.h), before the density.
template <int N>
struct MediumCoefficients {
  Spectrum<N> sigma_a, sigma_s, emission;
  // Textured coefficients (null: none): sigma_a + (sigma_a_to − sigma_a) t(x), and so for s.
  const Texture* sigma_a_texture = nullptr;
  const Texture* sigma_s_texture = nullptr;
  Spectrum<N> sigma_a_to{0.0}, sigma_s_to{0.0};
  // Set (a temperature grid): L_e varies and is evaluated per point at the channels below;
  // `emission` is then 0. Null for every medium of constant emission, which costs a test.
  const TemperatureEmission* emission_grid = nullptr;
  // Emission per unit length (Medium::j), a constant or, where j_grid is set, per point.
  Spectrum<N> j{0.0};
  const TemperatureEmission* j_grid = nullptr;
  bool spectral = false;           // the channels are wavelengths
  std::array<double, N> lambda{};  // their wavelengths (nm), in spectral mode
};

}  // namespace nimbus
