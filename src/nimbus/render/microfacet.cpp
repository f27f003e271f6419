#include "nimbus/render/microfacet.h"

#include <algorithm>
#include <cmath>

#include "nimbus/math/constants.h"
#include "nimbus/render/material.h"

namespace nimbus {

namespace {

double clamp_alpha(double alpha) {
  return std::max(alpha, kMinMicrofacetAlpha);
}

// Strictly on one side of the macro surface; false when either is on the horizon.
bool same_side(const Vec3& a, const Vec3& b) {
  return a.z * b.z > 0;
}

// f·|wi.z|/pdf of a sampled direction, G/G1(wo) = (1 + Λo)/(1 + Λo + Λi); finite once Λo is.
double sample_weight(double alpha, const Vec3& wo, const Vec3& wi) {
  return 1 / (1 + smith_lambda(alpha, wi) / (1 + smith_lambda(alpha, wo)));
}

// The ratio n(across)/n(wo's side) that the Fresnel equations and Snell's law see from wo.
double eta_seen_from(double eta, const Vec3& wo) {
  return wo.z > 0 ? eta : 1 / eta;
}

// The facet that scatters wo into wi through a dielectric interface: its normal on wo's side
// and the cosines wo·wm > 0 and wi·wm (> 0 reflecting, < 0 refracting).
struct DielectricFacet {
  Vec3 wm;
  double eta = 1;  // eta_seen_from(wo)
  double cos_o = 0, cos_i = 0;
  double len2 = 0;  // |wo + eta wi|² = (wo·wm + eta wi·wm)² when refracting, > 0
  bool reflected = false;
};

// Walter et al. 2007, eqs. 13 and 16. False when no facet on wo's side does it: wi on the
// horizon, or the half vector would leave wo or wi behind the facet.
bool find_dielectric_facet(double eta, const Vec3& wo, const Vec3& wi, DielectricFacet& facet) {
  const double zz = wo.z * wi.z;
  if (zz == 0) return false;
  facet.reflected = zz > 0;
  facet.eta = eta_seen_from(eta, wo);
  Vec3 h = facet.reflected ? wo + wi : wo + wi * facet.eta;
  facet.len2 = dot(h, h);
  if (!(facet.len2 > 0)) return false;
  h = h / std::sqrt(facet.len2);
  if (h.z * wo.z < 0) h = -h;
  facet.wm = h;
  facet.cos_o = dot(wo, h);
  facet.cos_i = dot(wi, h);
  const bool wi_in_place = facet.reflected ? facet.cos_i > 0 : facet.cos_i < 0;
  return same_side(h, wo) && facet.cos_o > 0 && wi_in_place;
}

// The Jacobian |dwm/dwi| of refraction, n_i² |wi·wm| / (n_o wo·wm + n_i wi·wm)² with n_o = 1
// (Walter et al. 2007, eq. 17); den2 is the denominator, > 0.
double refraction_jacobian(double eta, double cos_i, double den2) {
  return eta * eta * std::abs(cos_i) / den2;
}

}  // namespace

double ggx_d(double alpha, const Vec3& wm) {
  const double a2 = clamp_alpha(alpha) * clamp_alpha(alpha);
  // Walter et al. 2007, eq. 33 with tan²θ = (x² + y²)/z², times cos⁴θ: no division by wm.z.
  const double t = (wm.x * wm.x + wm.y * wm.y) / a2 + wm.z * wm.z;
  if (!(t > 0)) return 0;
  return 1 / (kPi * a2 * t * t);
}

double smith_lambda(double alpha, const Vec3& w) {
  const double z2 = w.z * w.z;
  if (z2 == 0) return kInf;
  const double a = clamp_alpha(alpha) * clamp_alpha(alpha) * (w.x * w.x + w.y * w.y) / z2;
  if (!(a < kInf)) return kInf;
  // Heitz 2014: (√(1 + α² tan²θ) − 1)/2 for GGX, written without the cancellation.
  return a / (2 * (1 + std::sqrt(1 + a)));
}

double smith_g1(double alpha, const Vec3& w) {
  return 1 / (1 + smith_lambda(alpha, w));
}

double smith_g(double alpha, const Vec3& wo, const Vec3& wi) {
  return 1 / (1 + smith_lambda(alpha, wo) + smith_lambda(alpha, wi));
}

Vec3 sample_visible_normal(double alpha, const Vec3& wo, double u1, double u2) {
  alpha = clamp_alpha(alpha);
  // From below, the facets seen are those seen from −wo, flipped.
  const double side = wo.z < 0 ? -1.0 : 1.0;
  const Vec3 v = wo * side;
  // Heitz 2018: stretch to the α = 1 configuration, where the visible normals are uniform
  // over the projected hemisphere: a disk, of which the part behind the hemisphere is squashed.
  const Vec3 vh = normalize(Vec3{alpha * v.x, alpha * v.y, v.z});
  const double len2 = vh.x * vh.x + vh.y * vh.y;
  const Vec3 t1 = len2 > 0 ? Vec3{-vh.y, vh.x, 0} / std::sqrt(len2) : Vec3{1, 0, 0};
  const Vec3 t2 = cross(vh, t1);
  const double r = std::sqrt(u1), phi = 2 * kPi * u2;
  const double p1 = r * std::cos(phi);
  const double s = 0.5 * (1 + vh.z);
  const double p2 = (1 - s) * std::sqrt(std::max(0.0, 1 - p1 * p1)) + s * r * std::sin(phi);
  const Vec3 nh = t1 * p1 + t2 * p2 + vh * std::sqrt(std::max(0.0, 1 - p1 * p1 - p2 * p2));
  // Back to the α configuration: normals transform by the inverse transpose of the stretch.
  const Vec3 wm = normalize(Vec3{alpha * nh.x, alpha * nh.y, std::max(0.0, nh.z)});
  return wm * side;
}

double visible_normal_pdf(double alpha, const Vec3& wo, const Vec3& wm) {
  const double c = dot(wo, wm);
  if (!same_side(wo, wm) || !(c > 0)) return 0;
  // Heitz 2018: the projected area of the visible facets of normal wm.
  return smith_g1(alpha, wo) * c * ggx_d(alpha, wm) / std::abs(wo.z);
}

double fresnel_conductor(double cos_i, double eta, double k) {
  const double c = std::clamp(cos_i, 0.0, 1.0);
  const double s2 = 1 - c * c;
  // w = a + i b = √(η̃² − sin²θ) = η̃ cos θ_t, the principal root (a, b ≥ 0), η̃ = η + i k.
  const double re = eta * eta - k * k - s2, im = 2 * eta * k;
  // The larger part first, the other from 2ab = im: no cancellation when k or η dominates.
  const double mod = std::hypot(re, im);
  double a, b;
  if (re >= 0) {
    a = std::sqrt(0.5 * (mod + re));
    b = a > 0 ? im / (2 * a) : 0.0;
  } else {
    b = std::sqrt(0.5 * (mod - re));
    a = im / (2 * b);
  }
  // r_s = (cos θ − w)/(cos θ + w); r_p = (η̃² cos θ − w)/(η̃² cos θ + w) (Fresnel, complex index).
  const double rs_num = (c - a) * (c - a) + b * b, rs_den = (c + a) * (c + a) + b * b;
  const double pr = re * c + s2 * c, pi = im * c;  // η̃² cos θ = (re + sin²θ + i im) cos θ
  const double rp_num = (pr - a) * (pr - a) + (pi - b) * (pi - b);
  const double rp_den = (pr + a) * (pr + a) + (pi + b) * (pi + b);
  // Both denominators vanish only at grazing incidence on a matched interface (η̃ = 1): 1 there,
  // as fresnel_dielectric gives.
  const double rs2 = rs_den > 0 ? rs_num / rs_den : 1.0;
  const double rp2 = rp_den > 0 ? rp_num / rp_den : 1.0;
  return 0.5 * (rs2 + rp2);
}

Vec3 reflection_half_vector(const Vec3& wo, const Vec3& wi) {
  const Vec3 h = wo + wi;
  const double len2 = dot(h, h);
  return len2 > 0 ? h / std::sqrt(len2) : Vec3{};
}

double conductor_microfacet(double alpha, const Vec3& wo, const Vec3& wi) {
  if (!same_side(wo, wi)) return 0;
  const Vec3 wm = reflection_half_vector(wo, wi);
  // Walter et al. 2007, eq. 20 without F.
  return ggx_d(alpha, wm) * smith_g(alpha, wo, wi) / (4 * std::abs(wo.z * wi.z));
}

double conductor_microfacet_pdf(double alpha, const Vec3& wo, const Vec3& wi) {
  if (!same_side(wo, wi)) return 0;
  const Vec3 wm = reflection_half_vector(wo, wi);
  const double c = dot(wo, wm);
  // Walter et al. 2007, eq. 14: the reflection Jacobian 1/(4 |wo·wm|).
  return c > 0 ? visible_normal_pdf(alpha, wo, wm) / (4 * c) : 0;
}

MicrofacetSample sample_conductor_microfacet(double alpha, const Vec3& wo, double u1, double u2) {
  if (wo.z == 0) return {};
  MicrofacetSample s;
  s.wm = sample_visible_normal(alpha, wo, u1, u2);
  const double c = dot(wo, s.wm);
  if (!(c > 0)) return {};
  s.wi = s.wm * (2 * c) - wo;
  if (!same_side(wo, s.wi)) return {};
  s.reflected = true;
  s.pdf = visible_normal_pdf(alpha, wo, s.wm) / (4 * c);
  if (!(s.pdf > 0 && s.pdf < kInf)) return {};
  s.weight = sample_weight(alpha, wo, s.wi);
  return s;
}

double dielectric_microfacet(double alpha, double eta, const Vec3& wo, const Vec3& wi) {
  DielectricFacet h;
  if (!find_dielectric_facet(eta, wo, wi, h)) return 0;
  const double dg = ggx_d(alpha, h.wm) * smith_g(alpha, wo, wi);
  const double F = fresnel_dielectric(h.cos_o, h.eta);
  const double zz = std::abs(wo.z * wi.z);
  if (h.reflected) return F * dg / (4 * zz);
  // Walter et al. 2007, eq. 21, times (n_i/n_o)²: no radiance scaling across the interface.
  return (1 - F) * dg * h.cos_o * refraction_jacobian(h.eta, h.cos_i, h.len2) / zz;
}

double dielectric_microfacet_pdf(double alpha, double eta, const Vec3& wo, const Vec3& wi) {
  DielectricFacet h;
  if (!find_dielectric_facet(eta, wo, wi, h)) return 0;
  const double pm = visible_normal_pdf(alpha, wo, h.wm);
  const double F = fresnel_dielectric(h.cos_o, h.eta);
  if (h.reflected) return pm * F / (4 * h.cos_o);
  return pm * (1 - F) * refraction_jacobian(h.eta, h.cos_i, h.len2);
}

MicrofacetSample sample_dielectric_microfacet(double alpha, double eta, const Vec3& wo,
                                              double u_choice, double u1, double u2) {
  if (wo.z == 0) return {};
  MicrofacetSample s;
  s.wm = sample_visible_normal(alpha, wo, u1, u2);
  const double c = dot(wo, s.wm);
  if (!(c > 0)) return {};
  const double e = eta_seen_from(eta, wo);
  const double F = fresnel_dielectric(c, e);
  const double pm = visible_normal_pdf(alpha, wo, s.wm);
  if (u_choice < F) {
    s.wi = s.wm * (2 * c) - wo;
    if (!same_side(wo, s.wi)) return {};
    s.reflected = true;
    s.pdf = pm * F / (4 * c);
  } else {
    // Snell's law about wm, as sample_dielectric about the macro normal; F < 1 here, so no
    // total internal reflection.
    const double cos_t = std::sqrt(std::max(0.0, 1 - (1 - c * c) / (e * e)));
    s.wi = -wo / e + s.wm * (c / e - cos_t);
    const double den = c - e * cos_t;  // 0 only when e = 1: straight through, no density
    if (!(wo.z * s.wi.z < 0) || !(den * den > 0)) return {};
    s.pdf = pm * (1 - F) * refraction_jacobian(e, cos_t, den * den);
  }
  if (!(s.pdf > 0 && s.pdf < kInf)) return {};
  s.weight = sample_weight(alpha, wo, s.wi);
  return s;
}

}  // namespace nimbus
