#include "nimbus/render/microfacet_albedo.h"

#include <algorithm>
#include <cmath>

#include "nimbus/math/rng.h"
#include "nimbus/render/material.h"
#include "nimbus/render/microfacet.h"

namespace nimbus {

double AlbedoCurve::at(double mu) const {
  const double x = std::clamp(mu, 0.0, 1.0) * (kNodes - 1);
  const int i = std::min(kNodes - 2, static_cast<int>(x));
  return E[size_t(i)] + (x - i) * (E[size_t(i + 1)] - E[size_t(i)]);
}

namespace {

// 32 × 32 stratified visible normals per node, the dielectric's choice from a fixed stream.
constexpr int kStrata = 32;

AlbedoCurve albedo_curve(const Surface& s, bool from_inside) {
  const bool conductor = s.type == Surface::Type::Conductor;
  AlbedoCurve curve;
  Rng rng(0x6d69637266616365ull, from_inside ? 1 : 0);
  double reflected_avg = 0;
  for (int i = 0; i < AlbedoCurve::kNodes; ++i) {
    // The horizon itself has no visible facets: its node takes a nearly grazing direction.
    const double mu = std::max(1e-3, double(i) / (AlbedoCurve::kNodes - 1));
    const Vec3 wo{std::sqrt(1 - mu * mu), 0, from_inside ? -mu : mu};
    double sum = 0, sum_reflected = 0;
    for (int a = 0; a < kStrata; ++a)
      for (int b = 0; b < kStrata; ++b) {
        const double u1 = (a + rng.uniform()) / kStrata, u2 = (b + rng.uniform()) / kStrata;
        const MicrofacetSample m =
            conductor ? sample_conductor_microfacet(s.roughness, wo, u1, u2)
                      : sample_dielectric_microfacet(s.roughness, s.ior, wo, rng.uniform(), u1, u2);
        if (!(m.pdf > 0)) continue;
        sum += m.weight;
        if (m.reflected || conductor) sum_reflected += m.weight;
      }
    curve.E[size_t(i)] = sum / (kStrata * kStrata);
    // 2 ∫ E μ dμ by the trapezoidal rule over the nodes.
    const double w = (i == 0 || i == AlbedoCurve::kNodes - 1 ? 0.5 : 1.0) /
                     (AlbedoCurve::kNodes - 1) * 2 * (double(i) / (AlbedoCurve::kNodes - 1));
    curve.average += w * curve.E[size_t(i)];
    reflected_avg += w * sum_reflected / (kStrata * kStrata);
  }
  curve.reflected = curve.average > 0 ? reflected_avg / curve.average : 1.0;
  return curve;
}

}  // namespace

MicrofacetAlbedo microfacet_albedo(const Surface& s) {
  MicrofacetAlbedo t;
  t.outside = albedo_curve(s, false);
  if (s.type == Surface::Type::Dielectric) t.inside = albedo_curve(s, true);
  return t;
}

MicrofacetAlbedoLevels microfacet_albedo_levels(const Surface& s) {
  MicrofacetAlbedoLevels l;
  l.alpha0 = l.alpha1 = s.roughness;
  if (!s.roughness_texture || s.roughness_to == s.roughness) {
    l.levels.push_back(microfacet_albedo(s));
    return l;
  }
  l.alpha1 = s.roughness_to;
  Surface at = s;
  for (int i = 0; i < MicrofacetAlbedoLevels::kLevels; ++i) {
    at.roughness = l.alpha0 + (l.alpha1 - l.alpha0) * i / (MicrofacetAlbedoLevels::kLevels - 1);
    l.levels.push_back(microfacet_albedo(at));
  }
  return l;
}

namespace {

AlbedoCurve blend(const AlbedoCurve& a, const AlbedoCurve& b, double w) {
  AlbedoCurve c;
  for (size_t i = 0; i < c.E.size(); ++i) c.E[i] = a.E[i] + w * (b.E[i] - a.E[i]);
  c.average = a.average + w * (b.average - a.average);
  c.reflected = a.reflected + w * (b.reflected - a.reflected);
  return c;
}

}  // namespace

const MicrofacetAlbedo* MicrofacetAlbedoLevels::at(double alpha,
                                                   std::optional<MicrofacetAlbedo>& scratch) const {
  if (levels.size() == 1) return &levels[0];
  const double x =
      std::clamp((alpha - alpha0) / (alpha1 - alpha0), 0.0, 1.0) * double(levels.size() - 1);
  const size_t i = std::min(levels.size() - 2, static_cast<size_t>(x));
  const double w = x - double(i);
  scratch.emplace();
  scratch->outside = blend(levels[i].outside, levels[i + 1].outside, w);
  scratch->inside = blend(levels[i].inside, levels[i + 1].inside, w);
  return &*scratch;
}

}  // namespace nimbus
