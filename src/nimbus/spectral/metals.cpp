#include "nimbus/spectral/metals.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "nimbus/spectral/spectral_curve.h"

namespace nimbus {
namespace {

// (wavelength in µm, n, k), as the sources tabulate them.
struct Sample {
  double um, n, k;
};

// P. B. Johnson and R. W. Christy, "Optical constants of the noble metals", Phys. Rev. B 6,
// 4370–4379 (1972): the rows from 0.3542 to 0.8920 µm.
const std::vector<Sample> kGold = {
    {0.3542, 1.50, 1.866}, {0.3679, 1.48, 1.895}, {0.3815, 1.46, 1.933}, {0.3974, 1.47, 1.952},
    {0.4133, 1.46, 1.958}, {0.4305, 1.45, 1.948}, {0.4509, 1.38, 1.914}, {0.4714, 1.31, 1.849},
    {0.4959, 1.04, 1.833}, {0.5209, 0.62, 2.081}, {0.5486, 0.43, 2.455}, {0.5821, 0.29, 2.863},
    {0.6168, 0.21, 3.272}, {0.6595, 0.14, 3.697}, {0.7045, 0.13, 4.103}, {0.7560, 0.14, 4.542},
    {0.8211, 0.16, 5.083}, {0.8920, 0.17, 5.663}};
const std::vector<Sample> kSilver = {
    {0.3542, 0.10, 1.419}, {0.3679, 0.07, 1.657}, {0.3815, 0.05, 1.864}, {0.3974, 0.05, 2.070},
    {0.4133, 0.05, 2.275}, {0.4305, 0.04, 2.462}, {0.4509, 0.04, 2.657}, {0.4714, 0.05, 2.869},
    {0.4959, 0.05, 3.093}, {0.5209, 0.05, 3.324}, {0.5486, 0.06, 3.586}, {0.5821, 0.05, 3.858},
    {0.6168, 0.06, 4.152}, {0.6595, 0.05, 4.483}, {0.7045, 0.04, 4.838}, {0.7560, 0.03, 5.242},
    {0.8211, 0.04, 5.727}, {0.8920, 0.04, 6.312}};
const std::vector<Sample> kCopper = {
    {0.3542, 1.37, 1.916}, {0.3679, 1.36, 1.975}, {0.3815, 1.33, 2.045}, {0.3974, 1.32, 2.116},
    {0.4133, 1.28, 2.207}, {0.4305, 1.25, 2.305}, {0.4509, 1.24, 2.397}, {0.4714, 1.25, 2.483},
    {0.4959, 1.22, 2.564}, {0.5209, 1.18, 2.608}, {0.5486, 1.02, 2.577}, {0.5821, 0.70, 2.704},
    {0.6168, 0.30, 3.205}, {0.6595, 0.22, 3.747}, {0.7045, 0.21, 4.205}, {0.7560, 0.24, 4.665},
    {0.8211, 0.26, 5.180}, {0.8920, 0.30, 5.768}};
// K. M. McPeak et al., "Plasmonic films can easily be better: rules and recipes", ACS Photonics
// 2, 326–333 (2015), thermally evaporated Al: every fifth row from 0.355 to 0.88 µm.
const std::vector<Sample> kAluminium = {
    {0.355, 0.291774119, 3.719829584}, {0.380, 0.335956002, 4.002607455},
    {0.405, 0.385211589, 4.281283449}, {0.430, 0.440996226, 4.559109307},
    {0.455, 0.501228231, 4.832828338}, {0.480, 0.568005038, 5.105940631},
    {0.505, 0.640306464, 5.374848125}, {0.530, 0.720793584, 5.641767754},
    {0.555, 0.808351698, 5.905288517}, {0.580, 0.908569739, 6.165184423},
    {0.605, 1.016073317, 6.417351867}, {0.630, 1.136328574, 6.663125590},
    {0.655, 1.275302761, 6.898361917}, {0.680, 1.426024482, 7.116287362},
    {0.705, 1.596346402, 7.311383032}, {0.730, 1.786398844, 7.475374294},
    {0.755, 2.005349601, 7.585211073}, {0.780, 2.231500036, 7.603853787},
    {0.805, 2.399438967, 7.486541749}, {0.830, 2.375277499, 7.288411569},
    {0.855, 2.148111401, 7.177700369}, {0.880, 1.854996083, 7.243411521}};

const std::vector<std::pair<std::string_view, const std::vector<Sample>*>> kMetals = {
    {"aluminium", &kAluminium}, {"copper", &kCopper}, {"gold", &kGold}, {"silver", &kSilver}};

// ((η − 1)² + k²) / ((η + 1)² + k²).
double normal_reflectance(double eta, double k) {
  return ((eta - 1) * (eta - 1) + k * k) / ((eta + 1) * (eta + 1) + k * k);
}

// The η that with k gives reflectance r at normal incidence: the smaller root of
// (1 − r) η² − 2 (1 + r) η + (1 − r)(1 + k²) = 0; where there is none (k alone reflects more than
// r), the double root, which comes closest.
double eta_for(double r, double k) {
  const double a = 1 - r, b = 1 + r;
  const double disc = b * b - a * a * (1 + k * k);
  return (b - std::sqrt(std::max(0.0, disc))) / a;
}

}  // namespace

const std::vector<std::string_view>& metal_names() {
  static const std::vector<std::string_view> names = [] {
    std::vector<std::string_view> n;
    for (const auto& m : kMetals) n.push_back(m.first);
    return n;
  }();
  return names;
}

std::optional<Metal> metal_by_name(std::string_view name) {
  const auto it =
      std::find_if(kMetals.begin(), kMetals.end(), [&](const auto& m) { return m.first == name; });
  if (it == kMetals.end()) return std::nullopt;
  std::vector<std::pair<double, double>> eta, k, r;
  for (const Sample& s : *it->second) {
    eta.emplace_back(1000 * s.um, s.n);
    k.emplace_back(1000 * s.um, s.k);
    r.emplace_back(1000 * s.um, normal_reflectance(s.n, s.k));
  }
  Metal m{from_curve(piecewise_linear_spectrum(std::move(eta)), SpectralRole::Unbounded),
          from_curve(piecewise_linear_spectrum(std::move(k)), SpectralRole::Unbounded)};
  const Rgb r_rgb = reflectance_to_rgb(piecewise_linear_spectrum(std::move(r)));
  for (int c = 0; c < 3; ++c)
    m.eta.rgb[c] = std::max(1e-3, eta_for(std::clamp(r_rgb[c], 0.0, 0.999), m.k.rgb[c]));
  return m;
}

}  // namespace nimbus
