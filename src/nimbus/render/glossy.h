#pragma once
// A rough conductor or rough dielectric boundary at one surface point, in world space and at a
// path's channels: the microfacet BSDFs of render/microfacet.h in the frame of the normal, with
// the conductor's Fresnel factor per channel. The path loop (render/integrator.h) samples lights
// and directions with it like a diffuse surface, to both sides of a dielectric.

#include <algorithm>
#include <cmath>
#include <optional>

#include "nimbus/math/constants.h"
#include "nimbus/render/material.h"
#include "nimbus/render/microfacet.h"
#include "nimbus/render/microfacet_albedo.h"
#include "nimbus/render/path_spectra.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

// A conductor's Fresnel reflectance at the channels of its index η + ik, at cos_i to the facet
// normal.
template <int N>
Spectrum<N> conductor_fresnel(const Spectrum<N>& eta, const Spectrum<N>& k, double cos_i) {
  Spectrum<N> F;
  for (int c = 0; c < N; ++c) F[c] = fresnel_conductor(cos_i, eta[c], k[c]);
  return F;
}

template <int N>
struct GlossySample {
  Vec3 wi;
  Spectrum<N> weight;  // f |cos| / pdf
  double pdf;
};

template <int N>
class Glossy {
 public:
  // n: the normal the BSDF's frame stands on, the outward one for a dielectric (its inside is
  // below) and the one on the path's side for a conductor. albedo: the surface's tables for the
  // multiple-scattering lobe (render/microfacet_albedo.h), or null for single scattering alone.
  // alpha: the GGX roughness at the point (roughness_at, material.h).
  Glossy(const Surface& s, double alpha, const PathSpectra<N>& ps, const Vec3& n,
         const MicrofacetAlbedo* albedo)
      : conductor_(s.type == Surface::Type::Conductor),
        alpha_(alpha),
        ior_(s.ior),
        n_(n),
        albedo_(albedo) {
    orthonormal_basis(n, u_, v_);
    if (conductor_) {
      eta_ = evaluate(s.eta, ps.ch);
      k_ = evaluate(s.k, ps.ch);
      if (albedo_) f_ms_ = multiple_scattering_fresnel();
    }
  }

  // The BSDF f(wo, wi), without the cosine.
  Spectrum<N> f(const Vec3& wo, const Vec3& wi) const { return f_local(local(wo), local(wi)); }

  double pdf(const Vec3& wo, const Vec3& wi) const { return pdf_local(local(wo), local(wi)); }

  // A direction from the visible normals, or from the multiple-scattering lobe with probability
  // 1 − E(μ_o); u_choice picks the lobe, then reflection or refraction. None where the sample is
  // discarded.
  std::optional<GlossySample<N>> sample(const Vec3& wo, double u_choice, double u1,
                                        double u2) const {
    const Vec3 lo = local(wo);
    if (!albedo_) {
      const MicrofacetSample m = single(lo, u_choice, u1, u2);
      if (!(m.pdf > 0) || !(m.weight > 0)) return std::nullopt;
      Spectrum<N> weight(m.weight);
      if (conductor_) weight *= conductor_fresnel(eta_, k_, std::abs(dot(lo, m.wm)));
      return GlossySample<N>{world(m.wi), weight, m.pdf};
    }
    const double q = lost(lo);
    Vec3 li;
    if (u_choice < q) {
      // The lobe of the energy single scattering loses: cosine-distributed on the side chosen.
      const bool reflect = conductor_ || u_choice / q < side(lo).reflected;
      const double r = std::sqrt(u1), phi = 2 * kPi * u2, z = std::sqrt(std::max(0.0, 1 - u1));
      li = {r * std::cos(phi), r * std::sin(phi), (lo.z > 0) == reflect ? z : -z};
    } else {
      const MicrofacetSample m = single(lo, (u_choice - q) / (1 - q), u1, u2);
      if (!(m.pdf > 0)) return std::nullopt;
      li = m.wi;
    }
    const double pdf = pdf_local(lo, li);
    if (!(pdf > 0)) return std::nullopt;
    const Spectrum<N> weight = f_local(lo, li) * (std::abs(li.z) / pdf);
    if (weight.is_black()) return std::nullopt;
    return GlossySample<N>{world(li), weight, pdf};
  }

 private:
  Vec3 local(const Vec3& w) const { return {dot(w, u_), dot(w, v_), dot(w, n_)}; }
  Vec3 world(const Vec3& l) const { return u_ * l.x + v_ * l.y + n_ * l.z; }

  MicrofacetSample single(const Vec3& lo, double u_choice, double u1, double u2) const {
    return conductor_ ? sample_conductor_microfacet(alpha_, lo, u1, u2)
                      : sample_dielectric_microfacet(alpha_, ior_, lo, u_choice, u1, u2);
  }

  // The albedo table of the side w is on.
  const AlbedoCurve& side(const Vec3& w) const {
    return w.z > 0 || conductor_ ? albedo_->outside : albedo_->inside;
  }

  // 1 − E(μ_o): the energy single scattering loses, the multiple-scattering lobe's albedo and the
  // probability of sampling it.
  double lost(const Vec3& lo) const {
    return std::clamp(1 - side(lo).at(std::abs(lo.z)), 0.0, 1.0);
  }

  // The multiple-scattering lobe (Kulla & Conty 2017): (1 − E(μ_o)) (1 − E(μ_i)) / (π (1 − E_avg)),
  // which has albedo 1 − E(μ_o); a dielectric's splits it between its sides by the share of
  // single scattering that reflects, each side's shape from that side's table.
  double lobe(const Vec3& lo, const Vec3& li) const {
    const bool same = lo.z * li.z > 0;
    if (conductor_ && !same) return 0;
    const AlbedoCurve& from = side(lo);
    const AlbedoCurve& to = same ? from : side(li);
    const double norm = kPi * (1 - to.average);
    if (!(norm > 1e-9)) return 0;
    const double share = conductor_ ? 1.0 : same ? from.reflected : 1 - from.reflected;
    return lost(lo) * share * std::max(0.0, 1 - to.at(std::abs(li.z))) / norm;
  }

  double lobe_pdf(const Vec3& lo, const Vec3& li) const {
    const bool same = lo.z * li.z > 0;
    if (conductor_) return same ? std::abs(li.z) / kPi : 0.0;
    return (same ? side(lo).reflected : 1 - side(lo).reflected) * std::abs(li.z) / kPi;
  }

  Spectrum<N> f_local(const Vec3& lo, const Vec3& li) const {
    Spectrum<N> f;
    if (conductor_) {
      const double d = conductor_microfacet(alpha_, lo, li);
      f = d > 0 ? conductor_fresnel(eta_, k_, std::abs(dot(lo, reflection_half_vector(lo, li)))) * d
                : Spectrum<N>(0.0);
    } else {
      f = Spectrum<N>(dielectric_microfacet(alpha_, ior_, lo, li));
    }
    if (!albedo_) return f;
    const double ms = lobe(lo, li);
    return ms > 0 ? f + (conductor_ ? f_ms_ * ms : Spectrum<N>(ms)) : f;
  }

  double pdf_local(const Vec3& lo, const Vec3& li) const {
    const double p = conductor_ ? conductor_microfacet_pdf(alpha_, lo, li)
                                : dielectric_microfacet_pdf(alpha_, ior_, lo, li);
    if (!albedo_) return p;
    const double q = lost(lo);
    return (1 - q) * p + q * lobe_pdf(lo, li);
  }

  // A coloured conductor's multiple scattering keeps F_avg of the light at each further bounce:
  // F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg)) (Kulla & Conty 2017), F_avg = 2 ∫ F(μ) μ dμ
  // by 8-point Gauss–Legendre quadrature, per channel.
  Spectrum<N> multiple_scattering_fresnel() const {
    static constexpr double x[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                    0.9602898564975363};
    static constexpr double w[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                    0.1012285362903763};
    const double e_avg = albedo_->outside.average;
    Spectrum<N> out;
    for (int c = 0; c < N; ++c) {
      double f_avg = 0;
      for (int i = 0; i < 4; ++i)
        for (const double mu : {0.5 * (1 - x[i]), 0.5 * (1 + x[i])})
          f_avg += w[i] * mu * fresnel_conductor(mu, eta_[c], k_[c]);  // 2 × ½ Σ w μ F
      const double denom = 1 - f_avg * (1 - e_avg);
      out[c] = denom > 0 ? f_avg * f_avg * e_avg / denom : 0.0;
    }
    return out;
  }

  bool conductor_;
  double alpha_, ior_;
  Vec3 n_, u_, v_;
  const MicrofacetAlbedo* albedo_;
  Spectrum<N> eta_{1.0}, k_{0.0}, f_ms_{0.0};
};

}  // namespace nimbus
