#pragma once
// The coefficients of a medium at one point, per channel: absorption mu_a, scattering mu_s and
// emission L_e (radiance emitted per unit absorption, so the source term is mu_a L_e).

#include "nimbus/spectral/spectrum.h"

namespace nimbus {

template <int N>
struct MediumSample {
  Spectrum<N> mu_a, mu_s, L_e;
  // Extinction mu_t = mu_a + mu_s.
  constexpr Spectrum<N> mu_t() const { return mu_a + mu_s; }
};

}  // namespace nimbus
