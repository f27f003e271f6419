#include "nimbus/spectral/planck.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "nimbus/spectral/color.h"

namespace nimbus {
namespace {

// The table spans u = 1/T in [0, 1/kTableKelvin]. In u, log(Y u) (Y the luminance) and the
// chromaticity rgb / Y are smooth up to u = 0 (T → ∞, where B → (c1/c2) T λ⁻⁴), so linear
// interpolation is accurate everywhere: the error falls as the step squared, and measured
// (tests/planck_test.cpp) it was at most 3.7e-6 with 4096 steps, near 6 000 K, and is below
// 1e-6 with 16384. Cooler than kTableKelvin a blackbody is invisible (below 1e-12 of its
// luminance at 1000 K); those temperatures are computed directly.
constexpr double kTableKelvin = 400;
constexpr int kTableSteps = 16384;
constexpr double kTableStep = 1 / kTableKelvin / kTableSteps;
// The temperature that stands for u = 0: B there differs from its limit by a relative 1e-8.
constexpr double kHottest = 1e12;

struct Node {
  double log_yu;  // log(Y u)
  Rgb chroma;     // rgb / Y
};

Node node_at(double kelvin) {
  const Rgb rgb = emission_to_rgb(planck_spectrum(kelvin));
  const double y = linear_srgb_to_xyz(rgb).y;
  return {std::log(y / kelvin), rgb / y};
}

const std::vector<Node>& table() {
  static const std::vector<Node> t = [] {
    std::vector<Node> nodes(kTableSteps + 1);
    nodes[0] = node_at(kHottest);
    for (int i = 1; i <= kTableSteps; ++i) nodes[i] = node_at(1 / (i * kTableStep));
    return nodes;
  }();
  return t;
}

// Below about 2 000 K a blackbody lies outside the sRGB gamut (its blue is negative), which rgb
// mode cannot use: clamped as from_curve (spectral_param.h) clamps a {"blackbody": K} colour.
Rgb clamped(Rgb rgb) {
  for (int c = 0; c < 3; ++c) rgb[c] = std::max(rgb[c], 0.0);
  return rgb;
}

// The table's luminance at T >= kTableKelvin and, if wanted, the chromaticity.
double table_luminance(double kelvin, Rgb* chroma) {
  const double x = 1 / kelvin / kTableStep;
  const int i = std::min(static_cast<int>(x), kTableSteps - 1);
  const double w = x - i;
  const std::vector<Node>& t = table();
  if (chroma) *chroma = t[i].chroma + (t[i + 1].chroma - t[i].chroma) * w;
  return std::exp(t[i].log_yu + w * (t[i + 1].log_yu - t[i].log_yu)) * kelvin;
}

}  // namespace

double planck_radiance(double lambda, double kelvin) {
  if (!(lambda > 0) || !(kelvin > 0)) return 0;
  const double l2 = lambda * lambda;
  // expm1 of a huge argument is +inf, giving 0 far on the short side.
  return kPlanckC1 / (l2 * l2 * lambda) / std::expm1(kPlanckC2 / (lambda * kelvin));
}

SpectralCurve planck_spectrum(double kelvin) {
  SpectralCurve s;
  s.type = SpectralCurve::Type::Blackbody;
  s.kelvin = kelvin;
  s.scale = planck_radiance(kPlanckC2 / (kWienX * kelvin), kelvin);
  return s;
}

Rgb planck_rgb(double kelvin) {
  if (!(kelvin > 0)) return Rgb(0.0);
  if (kelvin < kTableKelvin) return clamped(emission_to_rgb(planck_spectrum(kelvin)));
  Rgb chroma;
  const double y = table_luminance(kelvin, &chroma);
  return clamped(chroma * y);
}

double planck_luminance(double kelvin) {
  if (!(kelvin > 0)) return 0;
  if (kelvin < kTableKelvin) return linear_srgb_to_xyz(emission_to_rgb(planck_spectrum(kelvin))).y;
  return table_luminance(kelvin, nullptr);
}

}  // namespace nimbus
