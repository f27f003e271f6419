#include "nimbus/spectral/spectral_curve.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <string>

#include "nimbus/spectral/cie.h"
#include "nimbus/spectral/color.h"
#include "nimbus/spectral/planck.h"
#include "nimbus/spectral/spectral_tables.h"

namespace nimbus {
namespace {

using namespace spectral_tables;

// S(x) = 1/2 + x / (2 √(1 + x²)) (Jakob and Hanika 2019); beyond |x| = 1e150, x² would
// overflow, and S is 0 or 1 to double precision anyway.
double sigmoid(double x) {
  if (std::abs(x) > 1e150) return x > 0 ? 1 : 0;
  return 0.5 + 0.5 * x / std::sqrt(1 + x * x);
}

double wien_peak_nm(double kelvin) {
  return kPlanckC2 / (kWienX * kelvin);
}

// Planck's law divided by its value at Wien's peak, so 1 at the peak; 0 for λ <= 0.
double blackbody_shape(double kelvin, double lambda) {
  if (!(lambda > 0)) return 0;
  const double peak = wien_peak_nm(kelvin);
  const double r = peak / lambda;
  // expm1 of a huge argument is +inf, giving 0 far on the short side.
  return r * r * r * r * r * std::expm1(kWienX) / std::expm1(kPlanckC2 / (lambda * kelvin));
}

double piecewise_linear(const std::vector<std::pair<double, double>>& points, double lambda) {
  if (lambda <= points.front().first) return points.front().second;
  if (lambda >= points.back().first) return points.back().second;
  const auto hi = std::upper_bound(points.begin(), points.end(), lambda,
                                   [](double l, const auto& p) { return l < p.first; });
  const auto lo = std::prev(hi);
  const double t = (lambda - lo->first) / (hi->first - lo->first);
  return (1 - t) * lo->second + t * hi->second;
}

using ValueRange = std::pair<double, double>;

ValueRange ordered(double a, double b) {
  return a < b ? ValueRange{a, b} : ValueRange{b, a};
}

ValueRange times(const ValueRange& a, const ValueRange& b) {
  const double p[4] = {a.first * b.first, a.first * b.second, a.second * b.first,
                       a.second * b.second};
  return {*std::min_element(p, p + 4), *std::max_element(p, p + 4)};
}

// The exact bounds of d65_illuminant over [lo, hi]: it is linear between its 5 nm knots (and 0
// outside [kLambdaMin, kLambdaMax]), so the extremes are at lo, hi or a knot between them.
ValueRange d65_bounds(double lo, double hi) {
  ValueRange b = ordered(d65_illuminant(lo), d65_illuminant(hi));
  for (int i = 0; i < kBands; ++i) {
    const double lambda = kLambdaMin + i * kStep;
    if (lambda > lo && lambda < hi) {
      const double v = d65_illuminant(lambda);
      b = {std::min(b.first, v), std::max(b.second, v)};
    }
  }
  return b;
}

// The shape (without scale and D65) of each type.
double shape(const SpectralCurve& s, double lambda) {
  switch (s.type) {
    case SpectralCurve::Type::Constant:
      return 1;
    case SpectralCurve::Type::Sigmoid:
      return sigmoid((s.c0 * lambda + s.c1) * lambda + s.c2);
    case SpectralCurve::Type::PiecewiseLinear:
      return piecewise_linear(s.points, lambda);
    case SpectralCurve::Type::Blackbody:
      return blackbody_shape(s.kelvin, lambda);
  }
  return 0;
}

ValueRange shape_bounds(const SpectralCurve& s, double lo, double hi) {
  switch (s.type) {
    case SpectralCurve::Type::Constant:
      return {1, 1};
    case SpectralCurve::Type::Sigmoid: {
      // S is increasing, so the bounds are S at the quadratic's extremes: at the ends or at its
      // vertex −c1 / (2 c0).
      auto q = [&](double l) { return (s.c0 * l + s.c1) * l + s.c2; };
      ValueRange b = ordered(q(lo), q(hi));
      if (s.c0 != 0) {
        const double vertex = -s.c1 / (2 * s.c0);
        if (vertex > lo && vertex < hi) {
          b = {std::min(b.first, q(vertex)), std::max(b.second, q(vertex))};
        }
      }
      return {sigmoid(b.first), sigmoid(b.second)};
    }
    case SpectralCurve::Type::PiecewiseLinear: {
      // Linear between knots and constant beyond them: extremes at lo, hi or a knot between.
      ValueRange b = ordered(piecewise_linear(s.points, lo), piecewise_linear(s.points, hi));
      for (const auto& [lambda, v] : s.points) {
        if (lambda > lo && lambda < hi) b = {std::min(b.first, v), std::max(b.second, v)};
      }
      return b;
    }
    case SpectralCurve::Type::Blackbody: {
      // Increasing below Wien's peak and decreasing above it.
      const double peak = wien_peak_nm(s.kelvin);
      const double a = blackbody_shape(s.kelvin, lo), b = blackbody_shape(s.kelvin, hi);
      const double top = peak > lo && peak < hi ? blackbody_shape(s.kelvin, peak) : std::max(a, b);
      return {std::min(a, b), top};
    }
  }
  return {0, 0};
}

// The integration grid with the colour matching functions and D65 evaluated once.
struct Grid {
  std::array<Vec3, kGridPoints> cmf;  // grid weight · (x̄, ȳ, z̄) / cie_y_integral()
  std::array<double, kGridPoints> d65;
};

const Grid& grid() {
  static const Grid g = [] {
    Grid g;
    for (int k = 0; k < kGridPoints; ++k) {
      const double lambda = grid_lambda(k);
      g.cmf[k] = cie_xyz_bar(lambda) * (grid_weight(k) / cie_y_integral());
      g.d65[k] = d65_illuminant(lambda);
    }
    return g;
  }();
  return g;
}

// The sigmoid curve with coefficients c in the table's variable t.
SpectralCurve sigmoid_curve(const std::array<double, 3>& c) {
  const auto nm = to_nm(c[0], c[1], c[2]);
  SpectralCurve s;
  s.type = SpectralCurve::Type::Sigmoid;
  s.c0 = nm[0];
  s.c1 = nm[1];
  s.c2 = nm[2];
  return s;
}

// Gauss–Newton steps on interpolated coefficients: trilinear interpolation of the table misses
// the target by up to ~1e-3, and a few steps bring reflectance_to_rgb to it at round-off wherever
// a sigmoid reaches it. A step that does not reduce the residual is halved, and the polish stops
// when none does, so it never does worse than the table.
std::array<double, 3> polish(std::array<double, 3> c, const Rgb& target) {
  constexpr int kSteps = 6;
  constexpr double kDone = 1e-13;
  auto residual = [&](const std::array<double, 3>& k) {
    return reflectance_to_rgb(sigmoid_curve(k)) - target;
  };
  Rgb r = residual(c);
  double error = r.max_abs();
  for (int step = 0; step < kSteps && error > kDone; ++step) {
    double J[3][3];  // J[i][j] = ∂ r_i / ∂ c_j, by forward differences
    for (int j = 0; j < 3; ++j) {
      std::array<double, 3> k = c;
      const double h = 1e-7 * (1 + std::abs(c[j]));
      k[j] += h;
      const Rgb rj = residual(k);
      for (int i = 0; i < 3; ++i) J[i][j] = (rj[i] - r[i]) / h;
    }
    // Solve J d = −r by Cramer's rule.
    auto det3 = [](const double m[3][3]) {
      return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
             m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
             m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    };
    const double det = det3(J);
    if (!(std::abs(det) > 0) || !std::isfinite(det)) break;
    std::array<double, 3> d;
    for (int j = 0; j < 3; ++j) {
      double m[3][3];
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) m[i][k] = k == j ? -r[i] : J[i][k];
      d[j] = det3(m) / det;
    }
    bool improved = false;
    for (double t = 1; t > 1.0 / 64 && !improved; t *= 0.5) {
      const std::array<double, 3> k = {c[0] + t * d[0], c[1] + t * d[1], c[2] + t * d[2]};
      const Rgb rk = residual(k);
      if (rk.max_abs() < error) {
        c = k;
        r = rk;
        error = rk.max_abs();
        improved = true;
      }
    }
    if (!improved) break;
  }
  return c;
}

}  // namespace

double SpectralCurve::operator()(double lambda) const {
  const double v = scale * shape(*this, lambda);
  return illuminant ? v * d65_illuminant(lambda) : v;
}

std::pair<double, double> SpectralCurve::range(double lo, double hi) const {
  // With D65 the bound is the product of the two ranges: safe, but not tight where the curve's
  // and D65's extremes fall at different wavelengths.
  const ValueRange b = times(shape_bounds(*this, lo, hi), {scale, scale});
  return illuminant ? times(b, d65_bounds(lo, hi)) : b;
}

SpectralCurve constant_spectrum(double value) {
  SpectralCurve s;
  s.scale = value;
  return s;
}

SpectralCurve rgb_albedo_spectrum(const Rgb& rgb_in) {
  // The table covers [0, 1]³; anything else is clamped into it.
  Rgb rgb;
  for (int i = 0; i < 3; ++i) rgb[i] = std::clamp(rgb_in[i], 0.0, 1.0);
  if (rgb[0] == rgb[1] && rgb[1] == rgb[2]) return constant_spectrum(rgb[0]);

  // Not grey, so the largest component z is positive.
  const int l = rgb[0] >= rgb[1] ? (rgb[0] >= rgb[2] ? 0 : 2) : (rgb[1] >= rgb[2] ? 1 : 2);
  const double z = rgb[l];
  // Table order: z, y, x.
  const double coords[3] = {std::max(z, kZMin), rgb[(l + 2) % 3] / z, rgb[(l + 1) % 3] / z};
  static const auto z_nodes = [] {
    std::array<double, kZRes> n;
    for (int k = 0; k < kZRes; ++k) n[k] = z_node(k);
    return n;
  }();
  static const auto xy_nodes = [] {
    std::array<double, kXyRes> n;
    for (int i = 0; i < kXyRes; ++i) n[i] = xy_node(i);
    return n;
  }();
  int cell[3];
  double frac[3];
  for (int d = 0; d < 3; ++d) {
    const double* n = d == 0 ? z_nodes.data() : xy_nodes.data();
    const int size = d == 0 ? kZRes : kXyRes;
    cell[d] =
        std::clamp(static_cast<int>(std::upper_bound(n, n + size, coords[d]) - n) - 1, 0, size - 2);
    frac[d] = (coords[d] - n[cell[d]]) / (n[cell[d] + 1] - n[cell[d]]);
  }
  std::array<double, 3> c = {0, 0, 0};
  for (int corner = 0; corner < 8; ++corner) {
    double w = 1;
    int i[3];
    for (int d = 0; d < 3; ++d) {
      const int bit = corner >> d & 1;
      i[d] = cell[d] + bit;
      w *= bit ? frac[d] : 1 - frac[d];
    }
    const int index = table_index(l, i[0], i[1], i[2]);
    for (int j = 0; j < 3; ++j) c[j] += w * table_entry(index + j);
  }
  // Below kZMin, the curve at kZMin scaled down: reflectance_to_rgb is linear, so the scaled
  // curve keeps its chromaticity and reaches z.
  const double scale = std::min(1.0, z / kZMin);
  SpectralCurve s = sigmoid_curve(polish(c, rgb / scale));
  s.scale = scale;
  return s;
}

SpectralCurve rgb_unbounded_spectrum(const Rgb& rgb_in) {
  Rgb rgb;
  for (int i = 0; i < 3; ++i) rgb[i] = std::max(rgb_in[i], 0.0);
  if (rgb[0] == rgb[1] && rgb[1] == rgb[2]) return constant_spectrum(rgb[0]);
  // Halving puts the largest component at z = 1/2: on the table's first z slice (no
  // interpolation in z) and away from its saturated z = 1 end.
  const double scale = 2 * rgb.max();
  SpectralCurve s = rgb_albedo_spectrum(rgb / scale);
  s.scale *= scale;
  return s;
}

SpectralCurve rgb_illuminant_spectrum(const Rgb& rgb) {
  SpectralCurve s = rgb_unbounded_spectrum(rgb);
  s.illuminant = true;
  return s;
}

SpectralCurve piecewise_linear_spectrum(std::vector<std::pair<double, double>> points) {
  if (points.empty()) throw std::invalid_argument("piecewise linear spectrum: no points");
  for (size_t i = 0; i < points.size(); ++i) {
    if (!std::isfinite(points[i].first) || !std::isfinite(points[i].second)) {
      throw std::invalid_argument("piecewise linear spectrum: point " + std::to_string(i) +
                                  " is not finite");
    }
    if (i > 0 && !(points[i].first > points[i - 1].first)) {
      throw std::invalid_argument("piecewise linear spectrum: wavelengths must increase (point " +
                                  std::to_string(i) + ")");
    }
  }
  SpectralCurve s;
  s.type = SpectralCurve::Type::PiecewiseLinear;
  s.points = std::move(points);
  return s;
}

SpectralCurve blackbody_spectrum(double kelvin, double scale) {
  if (!(kelvin > 0) || !std::isfinite(kelvin)) {
    throw std::invalid_argument("blackbody spectrum: temperature must be positive");
  }
  SpectralCurve s;
  s.type = SpectralCurve::Type::Blackbody;
  s.kelvin = kelvin;
  const double y = emission_to_xyz(s).y;
  if (!(y > 0)) {
    throw std::invalid_argument("blackbody spectrum: no visible emission at " +
                                std::to_string(kelvin) + " K");
  }
  s.scale = scale / y;
  return s;
}

Vec3 emission_to_xyz(const SpectralCurve& s) {
  const Grid& g = grid();
  Vec3 xyz;
  for (int k = 0; k < kGridPoints; ++k) xyz += s(grid_lambda(k)) * g.cmf[k];
  return xyz;
}

Rgb emission_to_rgb(const SpectralCurve& s) {
  return xyz_to_linear_srgb(emission_to_xyz(s));
}

Rgb reflectance_to_rgb(const SpectralCurve& s) {
  // D65 normalised to luminance 1, so ∫ D65 ȳ = cie_y_integral(), which g.cmf divides by.
  const Grid& g = grid();
  Vec3 xyz;
  for (int k = 0; k < kGridPoints; ++k) xyz += s(grid_lambda(k)) * g.d65[k] * g.cmf[k];
  return xyz_to_linear_srgb(xyz);
}

}  // namespace nimbus
