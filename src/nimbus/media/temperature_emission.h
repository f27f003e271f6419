#pragma once
// A medium's emission from a temperature grid (issue 14; the Houdini and Blender fire
// convention): at a point x the medium emits L_e(x) = scale · B(λ, T(x)), Planck's radiance
// (spectral/planck.h) at T(x), the grid's temperature in kelvin trilinearly interpolated and 0
// outside its active voxels (vdb_density.h). Below kMinEmittingKelvin it emits nothing. In rgb
// mode L_e is the linear sRGB of that radiance, in spectral mode B at the path's wavelengths.

#include <array>
#include <memory>

#include "nimbus/math/vec3.h"
#include "nimbus/media/density.h"
#include "nimbus/media/vdb_density.h"
#include "nimbus/spectral/planck.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

// Below this a blackbody's visible radiance is under 1e-9 of its value at 1000 K (the Draper
// point, where a glow first shows, is 798 K), so cold voxels skip the exponentials.
inline constexpr double kMinEmittingKelvin = 500;

struct TemperatureEmission {
  DensityPtr kelvin;  // the temperature at a world point, a grid read as vdb_density.h reads one
  double scale = 1;   // multiplies B in W·m⁻²·sr⁻¹·nm⁻¹
};

// Reads the grid (params.quantity "temperature" in messages); throws VdbError as
// make_vdb_density does. Builds planck_rgb's table now rather than in the first lookup.
std::shared_ptr<const TemperatureEmission> make_temperature_emission(VdbParams params,
                                                                     double scale);

// L_e at x: in rgb mode (spectral false, N = 3) linear sRGB, else at the wavelengths `lambda`.
template <int N>
Spectrum<N> temperature_emission_at(const TemperatureEmission& e, const Vec3& x, bool spectral,
                                    const std::array<double, N>& lambda) {
  const double kelvin = e.kelvin->value(x, 1.0);
  if (!(kelvin >= kMinEmittingKelvin)) return Spectrum<N>(0.0);
  if constexpr (N == 3) {
    if (!spectral) return planck_rgb(kelvin) * e.scale;
  }
  Spectrum<N> Le;
  for (int i = 0; i < N; ++i) Le[i] = e.scale * planck_radiance(lambda[i], kelvin);
  return Le;
}

}  // namespace nimbus
