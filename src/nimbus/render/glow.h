#pragma once
// Emission per unit length (a medium's "emission_per_length", Medium::j; docs/media.md,
// "Emission per unit length"): the RTE's source term j, independent of mu_a and of the density, as
// Cycles' volume emission is. A medium that emits sigma_a L_e is collected where the trackers
// collide; j may glow where nothing collides (mu_t = 0), so it has an estimator of its own, the
// track length: between two tentative collisions t_k < t_{k+1} of a free flight the path weight w_k
// is constant, and w_k 1{the path is alive at t} estimates T(t) without bias at every t in between
// (the product over a Poisson process of the null weights is ratio tracking's estimate), so
//   Σ_k w_k ∫_{t_k}^{t_{k+1}} j(t) dt   estimates   ∫ T(t) j(t) dt,
// and each interval's integral is estimated by one uniform point in it per glowing object whose
// bounds the interval crosses. It needs no majorant, and scenes without such media draw nothing.

#include "nimbus/frep/tape.h"
#include "nimbus/math/box.h"
#include "nimbus/math/rng.h"
#include "nimbus/render/path_spectra.h"
#include "nimbus/render/scene.h"

namespace nimbus {

// j at x of glowing object i, 0 where its function is not positive.
template <int N>
Spectrum<N> glow_at(const Scene& scene, const PathSpectra<N>& ps, int i, const Vec3& x) {
  const SceneObject& obj = scene.objects[size_t(i)];
  if (!(evaluate(obj.tape, x) > 0)) return Spectrum<N>(0.0);
  const MediumCoefficients<N>& c = ps.media[size_t(obj.medium)];
  return c.j_grid ? temperature_emission_at<N>(*c.j_grid, x, c.spectral, c.lambda) : c.j;
}

// Estimates ∫_a^b j(ray(t)) dt (a < b, b may be infinite) seen from `inside` (a solid, or -1 for
// the field): calls f(u, (d − c) j(ray(u))) for each glowing object whose bounds hold [c, d] of
// the interval, u uniform in [c, d]. Inside a solid only its own medium is present.
template <int N, class F>
void glow_samples(const Scene& scene, const PathSpectra<N>& ps, const Ray& ray, int inside,
                  double a, double b, Rng& rng, F&& f) {
  if (scene.glowing_objects.empty() || !(b > a)) return;
  auto sample = [&](int i) {
    double c = a, d = b;
    if (!clip_ray(scene.objects[size_t(i)].bounds, ray, c, d) || !(d > c)) return;
    const double u = c + (d - c) * rng.uniform();
    const Spectrum<N> j = glow_at(scene, ps, i, ray.at(u));
    if (!j.is_black()) f(u, j * (d - c));
  };
  if (inside >= 0) {
    const int m = scene.objects[size_t(inside)].medium;
    if (m >= 0 && glows(scene.media[size_t(m)])) sample(inside);
    return;
  }
  for (int i : scene.glowing_objects)
    if (scene.objects[size_t(i)].surface.type == Surface::Type::None) sample(i);
}

}  // namespace nimbus
