#include "nimbus/media/temperature_emission.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace nimbus {

std::shared_ptr<const TemperatureEmission> make_temperature_emission(VdbParams params, double scale,
                                                                     double kelvin_scale,
                                                                     TemperatureEmission::Law law) {
  params.quantity = "temperature";
  auto e = std::make_shared<TemperatureEmission>();
  e->kelvin = make_vdb_density(params);
  e->scale = scale;
  e->kelvin_scale = kelvin_scale;
  e->law = law;
  planck_rgb(1000);
  return e;
}

double brightest_temperature_emission(const TemperatureEmission& e, double kelvin) {
  if (!(kelvin >= kMinEmittingKelvin)) return 0;
  // B's peak (beyond the visible where cool) bounds B at every wavelength, and B and its rgb
  // grow with T, so under Planck's law the hottest point is the brightest. Under the
  // Stefan–Boltzmann law a cool blackbody's luminance is spread over far-red wavelengths that
  // barely count in it, so the coolest may be: temperatures in between are tried too.
  auto at = [&](double k) {
    return temperature_emission_factor(e, k) *
           std::max(planck_rgb(k).max(), planck_spectrum(k).scale);
  };
  if (e.law == TemperatureEmission::Law::Planck) return at(kelvin);
  constexpr int kSteps = 64;
  double b = 0;
  for (int i = 0; i <= kSteps; ++i)
    b = std::max(
        b, at(kMinEmittingKelvin * std::pow(kelvin / kMinEmittingKelvin, double(i) / kSteps)));
  return b;
}

}  // namespace nimbus
