#include "nimbus/spectral/spectral_param.h"

#include <algorithm>

namespace nimbus {

void complete_spectrum(SpectralParam& p, SpectralRole role) {
  if (p.curve) return;
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
  return p;
}

}  // namespace nimbus
