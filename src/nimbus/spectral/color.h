#pragma once
// Linear sRGB (ITU-R BT.709 primaries, D65 white) and CIE XYZ.

#include "nimbus/math/vec3.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

Rgb xyz_to_linear_srgb(const Vec3& xyz);
Vec3 linear_srgb_to_xyz(const Rgb& rgb);

}  // namespace nimbus
