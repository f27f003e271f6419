#pragma once
// Phase functions: isotropic and Henyey–Greenstein (Henyey & Greenstein 1941).
//
// Convention: every direction is a unit *propagation* direction. The incoming light travels
// along w_in, the scattered light along w_out, and cos_theta = dot(w_in, w_out). So g > 0
// scatters forward (the light keeps going roughly the way it went), g < 0 backward. Phase
// functions are densities over the unit sphere of w_out: they integrate to 1 (no albedo).

#include <numbers>

#include "nimbus/math/constants.h"
#include "nimbus/math/vec3.h"

namespace nimbus {

// p_HG(cos θ) = (1 − g²) / (4π (1 + g² − 2 g cos θ)^{3/2}), |g| < 1; g = 0 gives 1/(4π).
double hg_phase(double cos_theta, double g);

// A new propagation direction around the unit vector `dir`, with density hg_phase(dot(dir, ·), g)
// over the sphere, from two uniforms in [0, 1): u1 picks cos θ by exact inversion of the HG
// cumulative distribution, u2 the azimuth φ = 2π u2 in the frame orthonormal_basis(dir).
Vec3 sample_hg(const Vec3& dir, double g, double u1, double u2);

// The inverse-CDF map u1 ↦ cos θ used by sample_hg (exposed for tests).
double sample_hg_cos_theta(double g, double u1);

// A Henyey–Greenstein phase function; g = 0 is the isotropic one.
struct Phase {
  double g = 0;
  double eval(const Vec3& w_in, const Vec3& w_out) const { return hg_phase(dot(w_in, w_out), g); }
  Vec3 sample(const Vec3& w_in, double u1, double u2) const { return sample_hg(w_in, g, u1, u2); }
};

}  // namespace nimbus
