#pragma once
// A participating medium at run time: coefficients per unit length, a phase function and a
// density model. The medium at x is density(x) · (sigma_a, sigma_s), emitting L_e.

#include "nimbus/media/cloud_density.h"
#include "nimbus/spectral/spectral_param.h"

namespace nimbus {

struct Medium {
  enum class Density { Constant, Field, Cloud };
  SpectralParam sigma_a, sigma_s;  // coefficients (role Unbounded)
  SpectralParam emission;          // L_e, entering the RTE as mu_a L_e (eq. 4) (role Illuminant)
  double g = 0;                    // Henyey–Greenstein asymmetry; 0 is isotropic
  Density density = Density::Constant;
  double scale = 1;    // multiplies every density model
  CloudDensity cloud;  // Cloud: density from F and noise
};

}  // namespace nimbus
