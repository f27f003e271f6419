#pragma once
// Wavelengths sampled per path in spectral mode (docs/spectra.md). One uniform number gives N
// stratified wavelengths over [kLambdaMin, kLambdaMax]: u_i = (u + i) / N mapped through the
// inverse CDF of a pdf that favours the visible,
//   p(λ) ∝ sech²(kVisibleA (λ − kVisibleMu)),
// whose CDF is closed form (tanh). Each λ_i has marginal density p restricted to its stratum
// times N, so (1/N) Σ_i f(λ_i) / p(λ_i) estimates ∫ f dλ without bias.

#include <array>

namespace nimbus {

inline constexpr double kLambdaMin = 360.0, kLambdaMax = 830.0;  // nm
inline constexpr double kVisibleMu = 538.0;                      // nm, where p peaks
inline constexpr double kVisibleA = 0.0072;                      // 1/nm, the peak's width

// p(λ) over [kLambdaMin, kLambdaMax] (integrates to 1 there; 0 outside).
double visible_wavelength_pdf(double lambda);
// The CDF of p, in [0, 1].
double visible_wavelength_cdf(double lambda);
// The inverse CDF: u in [0, 1) to λ.
double sample_visible_wavelength(double u);

template <int N>
struct SampledWavelengths {
  std::array<double, N> lambda{};  // nm
  std::array<double, N> pdf{};     // p(λ_i), the per-wavelength density above
  std::array<double, N> u{};       // the stratified number λ_i came from, (u + i) / N
};

template <int N>
SampledWavelengths<N> sample_wavelengths(double u) {
  SampledWavelengths<N> w;
  for (int i = 0; i < N; ++i) {
    w.u[i] = (u + i) / N;
    w.lambda[i] = sample_visible_wavelength(w.u[i]);
    w.pdf[i] = visible_wavelength_pdf(w.lambda[i]);
  }
  return w;
}

}  // namespace nimbus
