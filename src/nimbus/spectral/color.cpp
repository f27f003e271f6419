#include "nimbus/spectral/color.h"

namespace nimbus {
namespace {

// The matrices are derived here from the BT.709 primaries and the D65 white point, as
// IEC 61966-2-1 does (the standard then prints them rounded to 4 digits), rather than copied.
struct Mat3 {
  double m[3][3];
};

constexpr Mat3 inverse(const Mat3& a) {
  const auto& m = a.m;
  const double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
  const double c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
  const double c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
  const double inv_det = 1 / (m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02);
  return {{{c00 * inv_det, (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * inv_det,
            (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * inv_det},
           {c01 * inv_det, (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * inv_det,
            (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * inv_det},
           {c02 * inv_det, (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * inv_det,
            (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * inv_det}}};
}

// Columns are the XYZ of the primaries R, G, B at unit luminance scaled by S, where S is chosen
// so that RGB (1, 1, 1) is the white point with Y = 1.
constexpr Mat3 srgb_to_xyz_matrix() {
  constexpr double xy[3][2] = {{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}};
  constexpr double wx = 0.3127, wy = 0.3290;
  Mat3 p{};
  for (int j = 0; j < 3; ++j) {
    p.m[0][j] = xy[j][0] / xy[j][1];
    p.m[1][j] = 1;
    p.m[2][j] = (1 - xy[j][0] - xy[j][1]) / xy[j][1];
  }
  const double white[3] = {wx / wy, 1, (1 - wx - wy) / wy};
  const Mat3 pi = inverse(p);
  for (int j = 0; j < 3; ++j) {
    const double s = pi.m[j][0] * white[0] + pi.m[j][1] * white[1] + pi.m[j][2] * white[2];
    for (int i = 0; i < 3; ++i) p.m[i][j] *= s;
  }
  return p;
}

constexpr Mat3 kSrgbToXyz = srgb_to_xyz_matrix();
constexpr Mat3 kXyzToSrgb = inverse(kSrgbToXyz);

}  // namespace

Rgb xyz_to_linear_srgb(const Vec3& xyz) {
  const auto& m = kXyzToSrgb.m;
  return Rgb({m[0][0] * xyz.x + m[0][1] * xyz.y + m[0][2] * xyz.z,
              m[1][0] * xyz.x + m[1][1] * xyz.y + m[1][2] * xyz.z,
              m[2][0] * xyz.x + m[2][1] * xyz.y + m[2][2] * xyz.z});
}

Vec3 linear_srgb_to_xyz(const Rgb& rgb) {
  const auto& m = kSrgbToXyz.m;
  return {m[0][0] * rgb[0] + m[0][1] * rgb[1] + m[0][2] * rgb[2],
          m[1][0] * rgb[0] + m[1][1] * rgb[1] + m[1][2] * rgb[2],
          m[2][0] * rgb[0] + m[2][1] * rgb[1] + m[2][2] * rgb[2]};
}

}  // namespace nimbus
