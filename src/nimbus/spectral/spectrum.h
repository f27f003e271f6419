#pragma once
// Spectrum<N>: a fixed-size value per channel (N = 3 for RGB). Plain value type.

#include <algorithm>
#include <array>
#include <cmath>

namespace nimbus {

template <int N>
struct Spectrum {
  static constexpr int kChannels = N;
  std::array<double, N> v{};

  constexpr Spectrum() = default;
  constexpr explicit Spectrum(double s) { v.fill(s); }
  constexpr Spectrum(std::array<double, N> a) : v(a) {}

  constexpr double operator[](int i) const { return v[i]; }
  constexpr double& operator[](int i) { return v[i]; }

#define NIMBUS_SPECTRUM_OP(op)                                           \
  constexpr Spectrum& operator op##=(const Spectrum& b) {                \
    for (int i = 0; i < N; ++i) v[i] op## = b.v[i];                      \
    return *this;                                                        \
  }                                                                      \
  constexpr Spectrum& operator op##=(double s) {                         \
    for (int i = 0; i < N; ++i) v[i] op## = s;                           \
    return *this;                                                        \
  }                                                                      \
  friend constexpr Spectrum operator op(Spectrum a, const Spectrum& b) { \
    return a op## = b;                                                   \
  }                                                                      \
  friend constexpr Spectrum operator op(Spectrum a, double s) {          \
    return a op## = s;                                                   \
  }
  NIMBUS_SPECTRUM_OP(+)
  NIMBUS_SPECTRUM_OP(-)
  NIMBUS_SPECTRUM_OP(*)
  NIMBUS_SPECTRUM_OP(/)
#undef NIMBUS_SPECTRUM_OP
  friend constexpr Spectrum operator*(double s, Spectrum a) {
    return a *= s;
  }
  friend constexpr bool operator==(const Spectrum&, const Spectrum&) = default;

  constexpr double max() const {
    return *std::max_element(v.begin(), v.end());
  }
  constexpr double min() const {
    return *std::min_element(v.begin(), v.end());
  }
  // The largest magnitude over channels (weights may be negative).
  constexpr double max_abs() const {
    double m = 0;
    for (double x : v) m = std::max(m, x < 0 ? -x : x);
    return m;
  }
  constexpr double sum() const {
    double s = 0;
    for (double x : v) s += x;
    return s;
  }
  constexpr double average() const {
    return sum() / N;
  }
  constexpr bool is_black() const {
    for (double x : v)
      if (x != 0) return false;
    return true;
  }
};

template <int N>
Spectrum<N> exp(const Spectrum<N>& s) {
  Spectrum<N> r;
  for (int i = 0; i < N; ++i) r[i] = std::exp(s[i]);
  return r;
}

template <int N>
Spectrum<N> abs(const Spectrum<N>& s) {
  Spectrum<N> r;
  for (int i = 0; i < N; ++i) r[i] = std::abs(s[i]);
  return r;
}

using Rgb = Spectrum<3>;

}  // namespace nimbus
