#pragma once
// A medium's emission from a temperature grid (issue 14; the Houdini and Blender fire
// convention): at a point x the medium emits L_e(x) = scale · B(λ, T(x)), Planck's radiance
// (spectral/planck.h) at T(x), the grid's temperature in kelvin (its values times kelvin_scale)
// trilinearly interpolated and 0 outside its active voxels (vdb_density.h). Under the
// Stefan–Boltzmann law (Cycles' Principled Volume) it is B's colour at luminance
// scale · σ_SB T⁴ / π instead. Below kMinEmittingKelvin it emits nothing. In rgb mode L_e is the
// linear sRGB of that radiance, in spectral mode B at the path's wavelengths.

#include <array>
#include <memory>
#include <numbers>

#include "nimbus/math/vec3.h"
#include "nimbus/media/density.h"
#include "nimbus/media/vdb_density.h"
#include "nimbus/spectral/planck.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

// Below this a blackbody's visible radiance is under 1e-9 of its value at 1000 K (the Draper
// point, where a glow first shows, is 798 K), so cold voxels skip the exponentials.
inline constexpr double kMinEmittingKelvin = 500;

// Stefan–Boltzmann's constant, W·m⁻²·K⁻⁴ (exact SI).
inline constexpr double kStefanBoltzmann = 5.670374419e-8;

struct TemperatureEmission {
  enum class Law {
    Planck,          // L_e = scale · B(λ, T): brightness as a blackbody's
    StefanBoltzmann  // B's colour at luminance scale · σ_SB T⁴ / π (Cycles' blackbody)
  };
  DensityPtr kelvin;  // the temperature at a world point, a grid read as vdb_density.h reads one
  double scale = 1;   // multiplies B in W·m⁻²·sr⁻¹·nm⁻¹ (Planck), or the luminance
  double kelvin_scale = 1;  // multiplies the grid's values
  Law law = Law::Planck;
};

// Reads the grid (params.quantity "temperature" in messages); throws VdbError as
// make_vdb_density does. Builds planck_rgb's table now rather than in the first lookup.
std::shared_ptr<const TemperatureEmission> make_temperature_emission(
    VdbParams params, double scale, double kelvin_scale = 1,
    TemperatureEmission::Law law = TemperatureEmission::Law::Planck);

// What multiplies B(λ, T) under e's law at T >= kMinEmittingKelvin.
inline double temperature_emission_factor(const TemperatureEmission& e, double kelvin) {
  if (e.law == TemperatureEmission::Law::Planck) return e.scale;
  const double t2 = kelvin * kelvin;
  return e.scale * kStefanBoltzmann * t2 * t2 / std::numbers::pi / planck_luminance(kelvin);
}

// The largest value L_e takes at any channel or wavelength where the temperature is at most
// `kelvin` (for the films' exponent and the load's brightness check).
double brightest_temperature_emission(const TemperatureEmission& e, double kelvin);

// L_e at x: in rgb mode (spectral false, N = 3) linear sRGB, else at the wavelengths `lambda`.
template <int N>
Spectrum<N> temperature_emission_at(const TemperatureEmission& e, const Vec3& x, bool spectral,
                                    const std::array<double, N>& lambda) {
  const double kelvin = e.kelvin_scale * e.kelvin->value(x, 1.0);
  if (!(kelvin >= kMinEmittingKelvin)) return Spectrum<N>(0.0);
  const double factor = temperature_emission_factor(e, kelvin);
  if constexpr (N == 3) {
    if (!spectral) return planck_rgb(kelvin) * factor;
  }
  Spectrum<N> Le;
  for (int i = 0; i < N; ++i) Le[i] = factor * planck_radiance(lambda[i], kelvin);
  return Le;
}

}  // namespace nimbus
