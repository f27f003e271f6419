#pragma once
// Chandrasekhar's H-function for isotropic scattering and the diffuse reflection of a
// semi-infinite, homogeneous, isotropically scattering half-space: analytic references for
// tests of the transport integrator.
//
// H is evaluated from its closed-form integral (Chandrasekhar, Radiative Transfer, 1950, ch. V;
// the characteristic function for isotropic scattering is Ψ = ω/2, so T(z) = 1 − ω arctan(z)/z,
// and the substitution z = tan θ gives)
//
//   H(μ) = exp( −(μ/π) ∫_0^{π/2} ln(1 − ω θ cot θ) / (cos²θ + μ² sin²θ) dθ ),  0 < ω <= 1,
//
// with double-exponential (tanh–sinh) quadrature (Takahashi & Mori 1974), which is exact to
// rounding for the log singularity at θ = 0 when ω = 1 and for the peak of width μ at θ = π/2.

#include <cmath>
#include <numbers>

namespace nimbus::test {

// ∫_a^b f by tanh–sinh quadrature, halving the step until two levels agree to rel_tol. f is
// called as f(x − a, b − x), both distances computed without cancellation, so integrands with
// endpoint singularities can use whichever is small.
template <class F>
double tanh_sinh(F&& f, double a, double b, double rel_tol = 1e-14) {
  constexpr double kHalfPi = 0.5 * std::numbers::pi;
  constexpr double kTMax = 4.5;  // beyond, the weights underflow against any finite integrand
  const double r = 0.5 * (b - a);
  // The contribution of the node at t, scaled by the step later.
  auto term = [&](double t) {
    const double u = kHalfPi * std::sinh(t);
    const double d_a = 2 * r / (1 + std::exp(-2 * u));  // r (1 + tanh u)
    const double d_b = 2 * r / (1 + std::exp(2 * u));   // r (1 − tanh u)
    if (d_a <= 0 || d_b <= 0) return 0.0;
    const double sech = 2 / (std::exp(u) + std::exp(-u));
    return r * kHalfPi * std::cosh(t) * sech * sech * f(d_a, d_b);
  };
  double h = 0.5;
  double sum = term(0);
  for (double t = h; t <= kTMax; t += h) sum += term(t) + term(-t);
  double estimate = h * sum;
  for (int level = 0; level < 12; ++level) {
    h *= 0.5;
    for (double t = h; t <= kTMax; t += 2 * h) sum += term(t) + term(-t);  // the new odd nodes
    const double refined = h * sum;
    const bool converged = std::abs(refined - estimate) <= rel_tol * std::abs(refined);
    estimate = refined;
    if (converged) break;
  }
  return estimate;
}

// H(μ) for isotropic scattering with single-scattering albedo omega in (0, 1], μ in [0, 1].
inline double chandrasekhar_h(double mu, double omega) {
  // H(μ) = 1 + (ω/2) μ ln(1/μ) + O(μ) as μ → 0, which rounds to 1 below μ = 1e-17.
  if (mu <= 1e-17) return 1;
  // θ ∈ (0, π/2) with θ = d_a, and ε = π/2 − θ = d_b accurate near π/2 (cot θ = tan ε).
  auto integrand = [&](double theta, double eps) {
    double q;  // 1 − θ cot θ
    if (theta < 0.1) {
      // θ cot θ = 1 − θ²/3 − θ⁴/45 − 2θ⁶/945 − θ⁸/4725 − 2θ¹⁰/93555 − …
      const double s = theta * theta;
      q = s * (1.0 / 3 + s * (1.0 / 45 + s * (2.0 / 945 + s * (1.0 / 4725 + s * (2.0 / 93555)))));
    } else {
      q = 1 - theta * std::tan(eps);
    }
    const double one_minus = (1 - omega) + omega * q;  // 1 − ω θ cot θ
    const double sin_e = std::sin(eps), cos_e = std::cos(eps);
    return std::log(one_minus) / (sin_e * sin_e + mu * mu * cos_e * cos_e);  // cos θ = sin ε
  };
  const double integral = tanh_sinh(integrand, 0, 0.5 * std::numbers::pi);
  return std::exp(-mu / std::numbers::pi * integral);
}

// Radiance diffusely reflected by the half-space, observed at cosine mu, for a collimated beam
// of irradiance E (measured normal to the beam) incident at cosine mu0 (Chandrasekhar 1950,
// ch. IV): L_r = E ω/(4π) · μ₀/(μ + μ₀) · H(μ) H(μ₀).
inline double half_space_reflected_radiance(double E, double omega, double mu0, double mu) {
  return E * omega / (4 * std::numbers::pi) * mu0 / (mu + mu0) * chandrasekhar_h(mu, omega) *
         chandrasekhar_h(mu0, omega);
}

}  // namespace nimbus::test
