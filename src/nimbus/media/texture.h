#pragma once
// A solid texture as a parameter's driver (docs/scene-format.md, "Textures"): any density type
// (density.h: a constant, the object's own F, noise, turbulence, veins, a VDB grid), scaled and
// clamped to [0, 1], blends a parameter between two values, v(x) = from + (to − from) · t(x).
// A function of the point in 3-D needs no UV map.

#include <algorithm>

#include "nimbus/media/density.h"
#include "nimbus/spectral/spectral_param.h"

namespace nimbus {

struct Texture {
  DensityPtr pattern;  // null: no texture, the parameter is its "from" value
  double scale = 1;
  explicit operator bool() const { return bool(pattern); }
  // t(x) in [0, 1], where the holding object's function is F.
  double at(const Vec3& x, double F) const {
    return std::clamp(scale * pattern->value(x, F), 0.0, 1.0);
  }
};

// A textured parameter's RGB value at x: from where t is absent.
inline Rgb textured_rgb(const SpectralParam& from, const SpectralParam& to, const Texture& t,
                        const Vec3& x, double F) {
  return t ? from.rgb + (to.rgb - from.rgb) * t.at(x, F) : from.rgb;
}

}  // namespace nimbus
