#include "nimbus/media/noise.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "nimbus/math/rng.h"

namespace nimbus {
namespace {

constexpr double kLacunarity = 2.0;
constexpr double kGain = 0.5;
constexpr Vec3 kOctaveShift{19.31, 47.73, 73.17};

// S(t) = 6t⁵ − 15t⁴ + 10t³: S(0) = 0, S(1) = 1, S' and S'' vanish at both ends.
constexpr double fade(double t) {
  return t * t * t * (t * (t * 6 - 15) + 10);
}
constexpr double lerp(double a, double b, double s) {
  return a + s * (b - a);
}

// The lattice repeats every 256 cells, so a coordinate far out (past 2^52, where a double has no
// fraction left, and past 2^63, where it has no int64 for the cell) is reduced into one period
// first (exactly: fmod is exact); a coordinate that is not finite reads the origin's cell.
double wrapped(double v) {
  if (std::abs(v) < 0x1p52) return v;
  return std::isfinite(v) ? std::fmod(v, 256.0) : 0.0;
}

}  // namespace

Noise make_noise(uint64_t seed) {
  Noise n;
  Rng rng(seed, 0x6e6f697365ull);
  for (int i = 0; i < 256; ++i) n.perm[i] = static_cast<uint8_t>(i);
  for (int i = 255; i > 0; --i) {
    const int j = static_cast<int>(rng.uniform() * (i + 1));
    std::swap(n.perm[i], n.perm[j]);
  }
  for (Vec3& g : n.grad) {
    const double z = 1 - 2 * rng.uniform();
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    const double phi = 2 * std::numbers::pi * rng.uniform();
    g = {r * std::cos(phi), r * std::sin(phi), z};
  }
  return n;
}

double noise(const Noise& n, const Vec3& x_in) {
  const Vec3 x{wrapped(x_in.x), wrapped(x_in.y), wrapped(x_in.z)};
  const double fx = std::floor(x.x), fy = std::floor(x.y), fz = std::floor(x.z);
  const Vec3 t{x.x - fx, x.y - fy, x.z - fz};
  const auto ix = static_cast<uint8_t>(static_cast<int64_t>(fx) & 255);
  const auto iy = static_cast<uint8_t>(static_cast<int64_t>(fy) & 255);
  const auto iz = static_cast<uint8_t>(static_cast<int64_t>(fz) & 255);
  // g_c · (t − c) for the corner c = (cx, cy, cz).
  auto corner = [&](int cx, int cy, int cz) {
    const uint8_t h0 = n.perm[static_cast<uint8_t>(ix + cx)];
    const uint8_t h1 = n.perm[static_cast<uint8_t>(h0 + iy + cy)];
    const uint8_t h2 = n.perm[static_cast<uint8_t>(h1 + iz + cz)];
    return dot(n.grad[h2], t - Vec3{double(cx), double(cy), double(cz)});
  };
  const double sx = fade(t.x), sy = fade(t.y), sz = fade(t.z);
  const double x00 = lerp(corner(0, 0, 0), corner(1, 0, 0), sx);
  const double x10 = lerp(corner(0, 1, 0), corner(1, 1, 0), sx);
  const double x01 = lerp(corner(0, 0, 1), corner(1, 0, 1), sx);
  const double x11 = lerp(corner(0, 1, 1), corner(1, 1, 1), sx);
  return lerp(lerp(x00, x10, sy), lerp(x01, x11, sy), sz);
}

double fbm(const Noise& n, const Vec3& x, int octaves) {
  double sum = 0, amplitude = 1, frequency = 1;
  for (int k = 0; k < octaves; ++k) {
    sum += amplitude * noise(n, frequency * x + double(k) * kOctaveShift);
    amplitude *= kGain;
    frequency *= kLacunarity;
  }
  return sum;
}

double fbm_bound(int octaves) {
  double bound = 0, amplitude = kNoiseBound;
  for (int k = 0; k < octaves; ++k) {
    bound += amplitude;
    amplitude *= kGain;
  }
  return bound;
}

}  // namespace nimbus
