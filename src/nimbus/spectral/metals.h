#pragma once
// Named metals for the "conductor" surface: the complex index η + ik of gold, silver, copper
// (Johnson & Christy 1972) and aluminium (McPeak et al. 2015), measured at room temperature,
// as tabulated in the refractiveindex.info database (public domain, CC0), 354–892 nm.

#include <optional>
#include <string_view>
#include <vector>

#include "nimbus/spectral/spectral_param.h"

namespace nimbus {

struct Metal {
  SpectralParam eta, k;  // role Unbounded; rgb mode: see metal_by_name
};

// The names a scene may give, in the order an error message lists them.
const std::vector<std::string_view>& metal_names();

// The metal of that name: its measured η and k as piecewise-linear curves. In rgb mode k is the
// RGB projection of its curve and η, per channel, the index that with that k gives the RGB
// projection of the metal's reflectance at normal incidence, so rgb mode shows the metal's
// colour head-on. None for an unknown name.
std::optional<Metal> metal_by_name(std::string_view name);

}  // namespace nimbus
