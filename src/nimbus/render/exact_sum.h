#pragma once
// Exact sums of sample values: fixed point with kExactSumFractionBits fractional bits in a
// 128-bit integer, in units of 2^exponent (the film's exponent, film.h). Integer addition is
// exact and associative, so a pixel's sum does not depend on how its samples were split between
// threads, calls or processes, nor on the order in which the parts are merged: the film's
// pixels are then the same bits however the work was divided. Each value is rounded once, to
// the nearest multiple of 2^(exponent - 64) (5.4e-20 at exponent 0).

#include <array>
#include <cmath>

#include "nimbus/spectral/spectrum.h"

namespace nimbus {

__extension__ using int128 = __int128;  // GCC and Clang; __extension__ keeps -Wpedantic quiet

inline constexpr int kExactSumFractionBits = 64;
// The largest magnitude a value may have, in units of 2^exponent: a pixel holds at most 2^32
// samples, so its sum stays below 2^94 units of 2^-64, far inside the integer's range.
inline constexpr double kExactSumMaxValue = 0x1p62;

// v (|v| < kExactSumMaxValue · 2^exponent) in units of 2^(exponent - 64), rounded to nearest
// (ties to even).
inline int128 to_fixed(double v, int exponent = 0) {
  return static_cast<int128>(std::nearbyint(std::ldexp(v, kExactSumFractionBits - exponent)));
}

inline double from_fixed(int128 s, int exponent = 0) {
  return std::ldexp(static_cast<double>(s), exponent - kExactSumFractionBits);
}

// Three exact sums, one per RGB channel.
struct ExactRgb {
  std::array<int128, 3> c{};

  ExactRgb& operator+=(const ExactRgb& o) {
    for (int i = 0; i < 3; ++i) c[i] += o.c[i];
    return *this;
  }
  bool operator==(const ExactRgb&) const = default;
  // The value each channel's sum stands for, rounded to the nearest double.
  Rgb value(int exponent = 0) const {
    return Rgb(
        {from_fixed(c[0], exponent), from_fixed(c[1], exponent), from_fixed(c[2], exponent)});
  }
};

inline ExactRgb to_fixed(const Rgb& v, int exponent = 0) {
  return ExactRgb{{to_fixed(v[0], exponent), to_fixed(v[1], exponent), to_fixed(v[2], exponent)}};
}

}  // namespace nimbus
