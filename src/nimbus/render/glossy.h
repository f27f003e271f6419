#pragma once
// A rough conductor or rough dielectric boundary at one surface point, in world space and at a
// path's channels: the microfacet BSDFs of render/microfacet.h in the frame of the normal, with
// the conductor's Fresnel factor per channel. The path loop (render/integrator.h) samples lights
// and directions with it like a diffuse surface, to both sides of a dielectric.

#include <cmath>
#include <optional>

#include "nimbus/render/material.h"
#include "nimbus/render/microfacet.h"
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
  // below) and the one on the path's side for a conductor.
  Glossy(const Surface& s, const PathSpectra<N>& ps, const Vec3& n)
      : conductor_(s.type == Surface::Type::Conductor), alpha_(s.roughness), ior_(s.ior), n_(n) {
    orthonormal_basis(n, u_, v_);
    if (conductor_) {
      eta_ = evaluate(s.eta, ps.ch);
      k_ = evaluate(s.k, ps.ch);
    }
  }

  // The BSDF f(wo, wi), without the cosine.
  Spectrum<N> f(const Vec3& wo, const Vec3& wi) const {
    const Vec3 lo = local(wo), li = local(wi);
    if (!conductor_) return Spectrum<N>(dielectric_microfacet(alpha_, ior_, lo, li));
    const double f = conductor_microfacet(alpha_, lo, li);
    if (!(f > 0)) return Spectrum<N>(0.0);
    return conductor_fresnel(eta_, k_, std::abs(dot(lo, reflection_half_vector(lo, li)))) * f;
  }

  double pdf(const Vec3& wo, const Vec3& wi) const {
    const Vec3 lo = local(wo), li = local(wi);
    return conductor_ ? conductor_microfacet_pdf(alpha_, lo, li)
                      : dielectric_microfacet_pdf(alpha_, ior_, lo, li);
  }

  // A direction from the visible normals (u_choice picks reflection or refraction); none where
  // the sample is discarded.
  std::optional<GlossySample<N>> sample(const Vec3& wo, double u_choice, double u1,
                                        double u2) const {
    const Vec3 lo = local(wo);
    const MicrofacetSample m =
        conductor_ ? sample_conductor_microfacet(alpha_, lo, u1, u2)
                   : sample_dielectric_microfacet(alpha_, ior_, lo, u_choice, u1, u2);
    if (!(m.pdf > 0) || !(m.weight > 0)) return std::nullopt;
    Spectrum<N> weight(m.weight);
    if (conductor_) weight *= conductor_fresnel(eta_, k_, std::abs(dot(lo, m.wm)));
    return GlossySample<N>{world(m.wi), weight, m.pdf};
  }

 private:
  Vec3 local(const Vec3& w) const { return {dot(w, u_), dot(w, v_), dot(w, n_)}; }
  Vec3 world(const Vec3& l) const { return u_ * l.x + v_ * l.y + n_ * l.z; }

  bool conductor_;
  double alpha_, ior_;
  Vec3 n_, u_, v_;
  Spectrum<N> eta_{1.0}, k_{0.0};
};

}  // namespace nimbus
