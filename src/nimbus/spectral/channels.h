#pragma once
// What a path's N channels are (docs/spectra.md): in rgb mode the three RGB channels; in spectral
// mode N wavelengths drawn for the path, each with the bin of the majorant octree that holds it.
// Colour inputs are evaluated at a path's channels once, so everything downstream sees plain
// Spectrum<N> values in either mode.

#include <array>
#include <utility>

#include "nimbus/spectral/spectral_param.h"
#include "nimbus/spectral/spectrum.h"
#include "nimbus/spectral/wavelengths.h"

namespace nimbus {

// The octree's bins in spectral mode: kSpectralBins intervals of equal probability under the
// wavelength pdf, so a channel drawn from stratified number u lies in bin ⌊u · kSpectralBins⌋.
inline constexpr int kSpectralBins = 16;

// Bin b's wavelength interval [lo, hi] (nm), over which the octree bounds each medium's sigma_t.
inline std::pair<double, double> spectral_bin_wavelengths(int b) {
  return {sample_visible_wavelength(double(b) / kSpectralBins),
          b + 1 == kSpectralBins ? kLambdaMax
                                 : sample_visible_wavelength(double(b + 1) / kSpectralBins)};
}

template <int N>
struct Channels {
  bool spectral = false;
  SampledWavelengths<N> wl;  // spectral mode
  std::array<int, N> bin{};  // the majorant octree's bin holding each channel
  // Multiplies the bin's majorant to bound mu_t at the channel's own wavelength
  // (channel_majorant_factors in render/path_spectra.h); 1 in rgb mode.
  std::array<double, N> majorant_factor = [] {
    std::array<double, N> f;
    f.fill(1.0);
    return f;
  }();
};

// A colour input at the path's channels.
template <int N>
Spectrum<N> evaluate(const SpectralParam& p, const Channels<N>& ch) {
  Spectrum<N> s;
  if constexpr (N == 3) {
    if (!ch.spectral) return p.rgb;
  }
  for (int i = 0; i < N; ++i) s[i] = (*p.curve)(ch.wl.lambda[i]);
  return s;
}

}  // namespace nimbus
