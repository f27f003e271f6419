#pragma once
// Light seen in a smooth dielectric boundary's mirror direction, estimated at every sample that
// meets the boundary from outside rather than only by the share F of them that sampling reflects.
// A small bright light seen in a glass or marble surface (a sun's mirror image) is otherwise the
// noisiest part of the image: the path finds it only when it both reflects, with probability F
// (about 4 % head-on), and lands on the light, so its variance is about 1/F times this
// estimate's. No light-sampling technique covers these paths (the camera sees them through a
// specular vertex), with or without manifold sampling.
//
// The partition: the probe counts what the reflected ray meets first, a light's or an emissive
// surface's radiance or the environment's, times F and the transmittance on the way; a path that
// then samples the reflection counts no emission at the end of that segment (media on the way
// still emit and scatter into it as before). So the two share no path and miss none. Part of
// `integrator.manifold`, which covers the light that reaches a vertex through a smooth boundary.

#include <array>
#include <span>

#include "nimbus/math/ray.h"
#include "nimbus/render/counters.h"
#include "nimbus/render/material.h"
#include "nimbus/render/path_spectra.h"
#include "nimbus/render/scene.h"
#include "nimbus/render/tracking_policies.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

// Whether the dielectric vertex whose sample is ds, met by a ray travelling along d at outward
// normal n, has its mirror direction probed: from outside, where reflection is neither certain
// nor impossible.
inline bool probes_mirror(const DielectricSample& ds, const Vec3& d, const Vec3& n) {
  return dot(d, n) < 0 && ds.F > 0 && ds.F < 1;
}

// F times the radiance arriving at p (on a boundary with outward normal n, met along d from the
// medium of solid `inside`, or -1) from the mirror direction, times the policy's transmittance on
// the way; the caller multiplies by the path's throughput. Uses the path's stream.
template <int N, class Policy>
Spectrum<N> mirror_light(const Scene& scene, const PathSpectra<N>& ps, const Vec3& p, const Vec3& n,
                         const Vec3& d, double F, int inside, const Policy& policy, Rng& rng,
                         Counters& counters) {
  ++counters.manifold.mirror_probes;
  const Vec3 wr = d - n * (2 * dot(d, n));
  const Ray ray{offset_origin(scene, p, n, wr), wr};
  ++counters.surface_rays;
  const auto hit = intersect(scene, ray, kInf);
  Spectrum<N> Le(0.0);
  ShadowSegment seg{ray, kInf, inside, -1};
  if (!hit) {
    for (const int i : scene.lights_at_infinity) Le += light_emission(ps, scene, i);
  } else if (hit->light >= 0) {
    Le = light_emission(ps, scene, hit->light);
    seg.t_max = hit->t * kShadowShrink;
    seg.light = hit->light;
  } else {
    const SceneObject& obj = scene.objects[size_t(hit->object)];
    if (obj.surface.type != Surface::Type::Emissive ||
        !(dot(wr, outward_normal(obj, ray.at(hit->t))) < 0))
      return Spectrum<N>(0.0);
    Le = evaluate(obj.surface.radiance, ps.ch);
    seg.t_max = hit->t * kShadowShrink;
  }
  if (Le.is_black()) return Spectrum<N>(0.0);
  Spectrum<N> out;
  if (!policy.chain_term(scene, ps, std::span<const ShadowSegment>(&seg, 1), Le * F, 0.0, rng,
                         counters, out))
    return Spectrum<N>(0.0);
  return out;
}

}  // namespace nimbus
