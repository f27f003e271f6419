#include "nimbus/spectral/spectral_param.h"

#include <algorithm>

#include "nimbus/spectral/channels.h"

namespace nimbus {
namespace {

void fill_bin_max(SpectralParam& p) {
  p.bin_max.resize(kSpectralBins);
  for (int b = 0; b < kSpectralBins; ++b) {
    const auto [lo, hi] = spectral_bin_wavelengths(b);
    p.bin_max[b] = p.curve->range(lo, hi).second;
  }
}

}  // namespace

void complete_spectrum(SpectralParam& p, SpectralRole role) {
  // bin_max is refilled even for a curve that has one: compile_scene calls this just before it
  // builds the octrees from the curves, so the two cannot disagree after an edit of the curve.
  if (p.curve) {
    fill_bin_max(p);
    return;
  }
  switch (role) {
    case SpectralRole::Albedo:
      p.curve = rgb_albedo_spectrum(p.rgb);
      break;
    case SpectralRole::Unbounded:
      p.curve = rgb_unbounded_spectrum(p.rgb);
      break;
    case SpectralRole::Illuminant:
      p.curve = rgb_illuminant_spectrum(p.rgb);
      break;
  }
  fill_bin_max(p);
}

SpectralParam from_curve(SpectralCurve curve, SpectralRole role) {
  SpectralParam p;
  p.rgb = role == SpectralRole::Illuminant ? emission_to_rgb(curve) : reflectance_to_rgb(curve);
  // A spectrum outside the sRGB gamut projects to negative components, which rgb mode cannot use.
  for (int c = 0; c < 3; ++c) {
    p.rgb[c] = std::max(p.rgb[c], 0.0);
    if (role == SpectralRole::Albedo) p.rgb[c] = std::min(p.rgb[c], 1.0);
  }
  p.curve = std::move(curve);
  fill_bin_max(p);
  return p;
}

}  // namespace nimbus
