#pragma once
// Free-flight sampling in a homogeneous (or majorant) medium of rate mu_bar.

#include <cmath>

namespace nimbus {

// A distance with density mu_bar exp(−mu_bar s), from u uniform in [0, 1), by inversion:
// s = −ln(1 − u) / mu_bar (log1p keeps small u accurate; u < 1 keeps s finite).
inline double free_flight(double mu_bar, double u) {
  return -std::log1p(-u) / mu_bar;
}

}  // namespace nimbus
