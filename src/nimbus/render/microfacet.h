#pragma once
// Rough boundaries: the isotropic Trowbridge–Reitz (GGX) microfacet model, its visible-normal
// sampling, and the rough conductor and rough dielectric built on them (issue 42).
//
// Everything is in a local shading frame whose macro-surface normal is +z: the caller converts
// (render/sampling.h, from_local). Directions are unit vectors; as in render/material.h, wo
// points away from the surface towards where the path came from, wi towards where it goes next.
// alpha is GGX's α (the scene's roughness), in [0, 1]; every function clamps it to at least
// kMinMicrofacetAlpha, so that very small roughness stays finite.
//
// Facet normals wm are taken on wo's side (wm.z has the sign of wo.z): a facet seen from below is
// the same facet with its normal flipped, and the distribution is symmetric under wm → −wm.
//
// Samples: a MicrofacetSample with pdf == 0 is discarded (its direction left the side it must
// be on, or the input was degenerate); its weight is 0 and its wi the zero vector. The weight
// f·|wi.z|/pdf of a kept sample is G(wo, wi)/G1(wo), in [0, 1], for both BSDFs: the
// single-scattering model loses energy (the F = 1 conductor at α = 1 and 45° reflects 0.377:
// tests/microfacet_test.cpp), which issue 42's multiple-scattering compensation is to make up.

#include "nimbus/math/vec3.h"

namespace nimbus {

inline constexpr double kMinMicrofacetAlpha = 1e-4;

// GGX distribution of facet normals, normalised by ∫_{wm.z>0} D(wm) wm.z dwm = 1; even in wm.
double ggx_d(double alpha, const Vec3& wm);
// Smith's Λ for GGX, a function of tan²θ, the same on both sides; masking G1 = 1/(1 + Λ).
// Infinite at grazing (w.z == 0), where G1 = 0.
double smith_lambda(double alpha, const Vec3& w);
double smith_g1(double alpha, const Vec3& w);
// Height-correlated masking-shadowing 1/(1 + Λ(wo) + Λ(wi)) (Heitz 2014).
double smith_g(double alpha, const Vec3& wo, const Vec3& wi);

// A facet normal on wo's side, distributed as the normals visible from wo (Heitz 2018), with
// density visible_normal_pdf. wo may be in either hemisphere.
Vec3 sample_visible_normal(double alpha, const Vec3& wo, double u1, double u2);
// D_wo(wm) = G1(wo) max(0, wo·wm) D(wm) / |wo.z|; 0 unless wm is on wo's side.
double visible_normal_pdf(double alpha, const Vec3& wo, const Vec3& wm);

// Unpolarised Fresnel reflectance of a conductor of complex index eta + i k relative to the
// outside medium (eta ≥ 0, k ≥ 0), at cos_i in [0, 1]: the exact formula, one channel at a time.
// k = 0 gives fresnel_dielectric (total internal reflection included); eta = 0 or k → ∞ give 1.
double fresnel_conductor(double cos_i, double eta, double k);

struct MicrofacetSample {
  Vec3 wi;
  Vec3 wm;            // the sampled facet normal, on wo's side (the conductor's Fresnel cosine)
  double weight = 0;  // f·|wi.z|/pdf; the conductor's excludes its Fresnel factor
  double pdf = 0;     // solid-angle density of wi; 0: discarded
  bool reflected = false;
};

// The facet normal that reflects wo into wi: normalize(wo + wi), for wo and wi on one side;
// the zero vector when wi = −wo.
Vec3 reflection_half_vector(const Vec3& wo, const Vec3& wi);

// Rough conductor, reflection only, wo on either side: f = D(wm) G(wo, wi) / (4 |wo.z| |wi.z|),
// 0 unless wi is on wo's side; the caller multiplies by fresnel_conductor(|wo·wm|, ...) per
// channel, with wm = reflection_half_vector(wo, wi). Reciprocal: f(wo, wi) = f(wi, wo).
double conductor_microfacet(double alpha, const Vec3& wo, const Vec3& wi);
double conductor_microfacet_pdf(double alpha, const Vec3& wo, const Vec3& wi);
// wi reflects wo about a visible normal; pdf = D_wo(wm) / (4 |wo·wm|).
MicrofacetSample sample_conductor_microfacet(double alpha, const Vec3& wo, double u1, double u2);

// Rough dielectric (Walter et al. 2007) between the outside (+z side) and the inside (−z side),
// eta = n_inside / n_outside > 0 (not 1: a matched interface is no boundary, and refraction
// through it has no density); wo on either side.
// f includes the Fresnel factors and, like render/material.h's smooth dielectric, no 1/η²
// radiance factor (the path carries L/n², equal to L where camera and lights are, in n = 1).
// With n(w) the index on w's side, f(wo, wi) / n(wi)² = f(wi, wo) / n(wo)²; reflection is
// symmetric.
double dielectric_microfacet(double alpha, double eta, const Vec3& wo, const Vec3& wi);
double dielectric_microfacet_pdf(double alpha, double eta, const Vec3& wo, const Vec3& wi);
// Samples a visible normal, then reflects with probability F(wo·wm) (total internal reflection:
// F = 1), else refracts; the weight includes the Fresnel factors.
MicrofacetSample sample_dielectric_microfacet(double alpha, double eta, const Vec3& wo,
                                              double u_choice, double u1, double u2);

}  // namespace nimbus
