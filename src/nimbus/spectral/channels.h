#pragma once
// What a path's N channels are (docs/spectra.md): in rgb mode the three RGB channels; in spectral
// mode N wavelengths drawn for the path, each with the bin of the majorant octree that holds it.
// Colour inputs are evaluated at a path's channels once, so everything downstream sees plain
// Spectrum<N> values in either mode.

#include <array>

#include "nimbus/spectral/spectral_param.h"
#include "nimbus/spectral/spectrum.h"
#include "nimbus/spectral/wavelengths.h"

namespace nimbus {

// The octree's bins in spectral mode: kSpectralBins intervals of equal probability under the
// wavelength pdf, so a channel drawn from stratified number u lies in bin ⌊u · kSpectralBins⌋.
inline constexpr int kSpectralBins = 16;

template <int N>
struct Channels {
  bool spectral = false;
  SampledWavelengths<N> wl;  // spectral mode
  std::array<int, N> bin{};  // the majorant octree's bin holding each channel
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
