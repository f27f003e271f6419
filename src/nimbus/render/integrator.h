#pragma once
// The path tracer: radiance arriving along a camera ray, at a path's N channels
// (render/path_spectra.h). Instantiated once per channel count (render/render_channels.cpp.in).

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "nimbus/math/ray.h"
#include "nimbus/math/rng.h"
#include "nimbus/media/medium_field.h"
#include "nimbus/render/counters.h"
#include "nimbus/render/path_spectra.h"
#include "nimbus/render/sampling.h"
#include "nimbus/render/scene.h"
#include "nimbus/render/volume.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {
namespace integrator_detail {

inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr double kShadowShrink = 1 - 1e-7;

// What a path carries from vertex to vertex.
template <int N>
struct PathState {
  Spectrum<N> beta{1.0};
  int inside = -1;  // the solid (dielectric) object the path is in, or -1
  // The last vertex sampled the lights (next-event estimation), so a light the path hits next
  // is weighted by MIS; false at the camera, at specular surfaces and inside solids.
  bool light_sampled = false;
  double prev_pdf = 0;  // solid-angle pdf with which the current direction was sampled
  Vec3 prev_p;          // where it was sampled
};

// The solid object containing p (the camera may sit inside one).
inline int solid_containing(const Scene& scene, const Vec3& p) {
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& obj = scene.objects[i];
    if (obj.surface.type == Surface::Type::Dielectric && obj.bounds.contains(p) &&
        evaluate(obj.tape, p) > 0)
      return static_cast<int>(i);
  }
  return -1;
}

// One light sample for next-event estimation at p, with the scattering function's value there
// and the shadow ray's origin; none if the light cannot contribute.
template <int N>
struct LightCandidate {
  LightSample ls;
  Spectrum<N> f;
  Spectrum<N> Li;  // falloff times the light's emission at the path's channels
  Vec3 origin;
};

template <int N, class F>
std::optional<LightCandidate<N>> light_candidate(const Scene& scene, const PathSpectra<N>& ps,
                                                 int light_index, const Vec3& p, const Vec3& n,
                                                 bool on_surface, F&& f, Rng& rng) {
  const Light& light = scene.lights[light_index];
  const double u1 = rng.uniform(), u2 = rng.uniform();
  const auto ls = sample_light(light, p, u1, u2);
  if (!ls) return std::nullopt;
  if (on_surface && dot(ls->wi, n) <= 0) return std::nullopt;
  const Spectrum<N> fv = f(ls->wi);
  if (fv.is_black()) return std::nullopt;
  return LightCandidate<N>{*ls, fv, ps.lights[light_index] * ls->falloff,
                           on_surface ? offset_origin(scene, p, n, ls->wi) : p};
}

// Light reaching p along one sample of every light (next-event estimation), times the
// scattering function `f(wi)` (cosine included for surfaces) and the transmittance through media;
// MIS with the sampling of f for lights that sampling can hit.
// `channel`: as for transmittance (delta tracking's channel, or -1 for all).
template <int N, class F, class Pdf>
Spectrum<N> direct_light(const Scene& scene, const PathSpectra<N>& ps, const Vec3& p, const Vec3& n,
                         bool on_surface, int inside, int channel, F&& f, Pdf&& f_pdf, Rng& rng,
                         Counters& counters) {
  Spectrum<N> L(0.0);
  for (int i = 0; i < static_cast<int>(scene.lights.size()); ++i) {
    const auto cand = light_candidate(scene, ps, i, p, n, on_surface, f, rng);
    if (!cand) continue;
    const LightSample* ls = &cand->ls;
    const Spectrum<N>& fv = cand->f;
    const Vec3& o = cand->origin;
    const Spectrum<N> T = transmittance(scene, ps, {o, ls->wi}, ls->distance * kShadowShrink, i,
                                        inside, channel, rng, counters);
    if (T.is_black()) continue;
    if (ls->delta)
      L += fv * cand->Li * T;
    else
      L += fv * cand->Li * T * (power_heuristic(ls->pdf, f_pdf(ls->wi)) / ls->pdf);
  }
  return L;
}

// Largest magnitude over channels: spectral tracking with a majorant that does not bound can
// make weights negative.
template <int N>
double max_abs(const Spectrum<N>& x) {
  double m = 0;
  for (int c = 0; c < N; ++c) m = std::max(m, std::abs(x[c]));
  return m;
}

// A scattering direction from the mixture phase function at a medium point, with its
// per-channel weight (phase value / pdf) and pdf.
template <int N>
struct PhaseSample {
  Vec3 wi;
  Spectrum<N> weight;
  double pdf;
};

template <int N>
PhaseSample<N> draw_phase(const MediumPoint<N>& m, const Vec3& dir, Rng& rng) {
  const double u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
  PhaseSample<N> ps;
  ps.wi = sample_phase(m, dir, u0, u1, u2, ps.weight, ps.pdf);
  return ps;
}

// Continues the path with probability q = min(1, max|beta / scale|) from depth 3 on.
template <int N>
bool russian_roulette(Spectrum<N>& beta, double scale, int depth, Rng& rng) {
  if (depth < 3) return true;
  const double q = std::min(1.0, max_abs(beta) / scale);
  if (q <= 0 || rng.uniform() >= q) return false;
  beta /= q;  // unbiased: survivors carry 1/q
  return true;
}

// Next-event estimation for spectral MIS (Miller et al. 2019, §6; pbrt-v4's SampleLd): the
// shadow ray's T_ray, r_u and r_l from hero ratio tracking, the vertex pdfs folded in with r_p,
// the path's r_u at the vertex, and the balance heuristic over channels and both techniques:
//   f Li T_ray / avg(r_p (p_light r_l + p_f r_u)),  or f Li T_ray / avg(r_p r_l) for delta lights.
template <int N, class F, class Pdf>
Spectrum<N> direct_light_mis(const Scene& scene, const PathSpectra<N>& ps, const Vec3& p,
                             const Vec3& n, bool on_surface, int inside, int hero,
                             const Spectrum<N>& r_p, F&& f, Pdf&& f_pdf, Rng& rng,
                             Counters& counters) {
  Spectrum<N> L(0.0);
  for (int i = 0; i < static_cast<int>(scene.lights.size()); ++i) {
    const auto cand = light_candidate(scene, ps, i, p, n, on_surface, f, rng);
    if (!cand) continue;
    const LightSample* ls = &cand->ls;
    const Spectrum<N>& fv = cand->f;
    const Vec3& o = cand->origin;
    MisPath<N> shadow;
    if (!transmittance_mis(scene, ps, {o, ls->wi}, ls->distance * kShadowShrink, i, inside, hero,
                           shadow, rng, counters))
      continue;
    if (ls->delta) {
      L += fv * cand->Li * shadow.beta / (r_p * shadow.r_l).average();
    } else {
      const Spectrum<N> r_l = r_p * shadow.r_l * ls->pdf, r_u = r_p * shadow.r_u * f_pdf(ls->wi);
      L += fv * cand->Li * shadow.beta / (r_l + r_u).average();
    }
  }
  return L;
}

// The path tracer for spectral MIS: one hero channel per path for free-path sampling, every
// contribution divided by the channel-averaged path pdfs (beta / avg(r_u), or
// beta / avg(r_u + r_l) against next-event estimation). Surfaces as in `radiance`.
template <int N>
Spectrum<N> radiance_spectral_mis(const Scene& scene, const PathSpectra<N>& ps, Ray ray, Rng& rng,
                                  Counters& counters) {
  Spectrum<N> L(0.0);
  MisPath<N> path;
  const int hero = std::min(N - 1, static_cast<int>(rng.uniform() * N));
  int inside = solid_containing(scene, ray.o);
  bool light_sampled = false;  // as PathState::light_sampled
  Vec3 prev_p = ray.o;
  // Radiance Le arriving along the ray from `light`, which next-event estimation also samples.
  auto from_light = [&](int light_index) {
    const Light& light = scene.lights[light_index];
    const Spectrum<N>& Le = ps.lights[light_index];
    if (!light_sampled) return path.beta * Le / path.r_u.average();
    const Spectrum<N> r_l = path.r_l * light_pdf(light, prev_p, ray.d);
    return path.beta * Le / (path.r_u + r_l).average();
  };

  for (int depth = 0;; ++depth) {
    ++counters.surface_rays;
    const auto hit = intersect(scene, ray, kInf);
    const double t_surface = hit ? hit->t : kInf;
    const MediumEvent<N> ev =
        sample_collision_mis(scene, ps, ray, t_surface, inside, hero, path, rng, counters);
    L += ev.emitted;
    if (ev.type == MediumEvent<N>::Type::Absorb) break;
    if (ev.type == MediumEvent<N>::Type::Scatter) {
      if (depth >= scene.settings.max_depth) break;
      const Vec3 p = ray.at(ev.t);
      const MediumPoint<N>& m = ev.medium;
      if (inside < 0)
        L += path.beta * direct_light_mis(
                             scene, ps, p, {}, false, inside, hero, path.r_u,
                             [&](const Vec3& wi) { return phase_value(m, dot(ray.d, wi)); },
                             [&](const Vec3& wi) { return phase_pdf(m, dot(ray.d, wi)); }, rng,
                             counters);
      const PhaseSample<N> phase = draw_phase(m, ray.d, rng);
      path.beta *= phase.weight;
      path.r_l = path.r_u / phase.pdf;
      prev_p = p;
      light_sampled = inside < 0;
      ray = {p, phase.wi};
      if (!russian_roulette(path.beta, path.r_u.average(), depth, rng)) break;
      continue;
    }

    if (!hit) {
      for (size_t i = 0; i < scene.lights.size(); ++i)
        if (scene.lights[i].type == Light::Type::Environment) L += from_light(int(i));
      break;
    }
    if (hit->light >= 0) {
      L += from_light(hit->light);
      break;
    }
    const SceneObject& obj = scene.objects[hit->object];
    const Vec3 p = ray.at(hit->t);
    const Vec3 n = outward_normal(obj, p);
    if (obj.surface.type == Surface::Type::Emissive) {
      if (dot(ray.d, n) < 0)
        L += path.beta * evaluate(obj.surface.radiance, ps.ch) / path.r_u.average();
      break;
    }
    if (depth >= scene.settings.max_depth) break;

    if (obj.surface.type == Surface::Type::Diffuse) {
      const Vec3 ns = dot(ray.d, n) < 0 ? n : -n;
      const Spectrum<N> albedo = evaluate(obj.surface.albedo, ps.ch);
      const Spectrum<N> f = albedo * kInvPi;
      L += path.beta * direct_light_mis(
                           scene, ps, p, ns, true, inside, hero, path.r_u,
                           [&](const Vec3& wi) { return f * dot(wi, ns); },
                           [&](const Vec3& wi) { return dot(wi, ns) * kInvPi; }, rng, counters);
      const double u1 = rng.uniform(), u2 = rng.uniform();
      const Vec3 wi = sample_cosine_hemisphere(ns, u1, u2);
      path.beta *= albedo;
      path.r_l = path.r_u / (dot(wi, ns) * kInvPi);
      prev_p = p;
      light_sampled = true;
      ray = {offset_origin(scene, p, ns, wi), wi};
    } else {
      const DielectricSample ds = sample_dielectric(-ray.d, n, obj.surface.ior, rng.uniform());
      if (!ds.reflected) inside = dot(ds.wi, n) < 0 ? hit->object : -1;
      light_sampled = false;
      ray = {offset_origin(scene, p, n, ds.wi), ds.wi};
    }
    if (!russian_roulette(path.beta, path.r_u.average(), depth, rng)) break;
  }
  return L;
}

}  // namespace integrator_detail

template <int N>
Spectrum<N> radiance(const Scene& scene, const PathSpectra<N>& ps, Ray ray, Rng& rng,
                     Counters& counters) {
  using namespace integrator_detail;
  ++counters.paths;
  if (scene.settings.tracking.mode == TrackingSettings::Mode::SpectralMis)
    return radiance_spectral_mis(scene, ps, ray, rng, counters);
  Spectrum<N> L(0.0);
  PathState<N> s;
  s.prev_p = ray.o;
  s.inside = solid_containing(scene, ray.o);
  // Delta tracking follows one channel per path, chosen uniformly when the path first meets a
  // medium (sample_collision), and from then on carries its weight (times N) to that channel only.
  int channel = -1;

  auto mis_weight = [&](const Light& light) {
    return s.light_sampled ? power_heuristic(s.prev_pdf, light_pdf(light, s.prev_p, ray.d)) : 1.0;
  };

  for (int depth = 0;; ++depth) {
    ++counters.surface_rays;
    const auto hit = intersect(scene, ray, kInf);
    const double t_surface = hit ? hit->t : kInf;

    const MediumEvent<N> ev =
        sample_collision(scene, ps, ray, t_surface, s.inside, s.beta, channel, rng, counters);
    L += ev.emitted;
    if (ev.type == MediumEvent<N>::Type::Absorb) break;
    if (ev.type == MediumEvent<N>::Type::Scatter) {
      if (depth >= scene.settings.max_depth) break;
      const Vec3 p = ray.at(ev.t);
      const MediumPoint<N>& m = ev.medium;
      // A solid's boundary is specular: no shadow ray can leave it, so skip NEE inside one (a
      // light inside it is then found by phase sampling alone, with weight 1).
      if (s.inside < 0)
        L += s.beta * direct_light(
                          scene, ps, p, {}, false, s.inside, channel,
                          [&](const Vec3& wi) { return phase_value(m, dot(ray.d, wi)); },
                          [&](const Vec3& wi) { return phase_pdf(m, dot(ray.d, wi)); }, rng,
                          counters);
      const PhaseSample<N> phase = draw_phase(m, ray.d, rng);
      s.beta *= phase.weight;
      s.prev_pdf = phase.pdf;
      s.prev_p = p;
      s.light_sampled = s.inside < 0;
      ray = {p, phase.wi};
      if (!russian_roulette(s.beta, 1.0, depth, rng)) break;
      continue;
    }

    if (!hit) {
      for (size_t i = 0; i < scene.lights.size(); ++i)
        if (scene.lights[i].type == Light::Type::Environment)
          L += s.beta * ps.lights[i] * mis_weight(scene.lights[i]);
      break;
    }
    if (hit->light >= 0) {
      L += s.beta * ps.lights[hit->light] * mis_weight(scene.lights[hit->light]);
      break;
    }
    const SceneObject& obj = scene.objects[hit->object];
    const Vec3 p = ray.at(hit->t);
    const Vec3 n = outward_normal(obj, p);
    if (obj.surface.type == Surface::Type::Emissive) {
      if (dot(ray.d, n) < 0) L += s.beta * evaluate(obj.surface.radiance, ps.ch);
      break;
    }
    if (depth >= scene.settings.max_depth) break;

    if (obj.surface.type == Surface::Type::Diffuse) {
      const Vec3 ns = dot(ray.d, n) < 0 ? n : -n;  // facing the incoming ray
      const Spectrum<N> albedo = evaluate(obj.surface.albedo, ps.ch);
      const Spectrum<N> f = albedo * kInvPi;
      L += s.beta * direct_light(
                        scene, ps, p, ns, true, s.inside, channel,
                        [&](const Vec3& wi) { return f * dot(wi, ns); },
                        [&](const Vec3& wi) { return dot(wi, ns) * kInvPi; }, rng, counters);
      const double u1 = rng.uniform(), u2 = rng.uniform();
      const Vec3 wi = sample_cosine_hemisphere(ns, u1, u2);
      s.beta *= albedo;  // f cos / pdf = albedo
      s.prev_pdf = dot(wi, ns) * kInvPi;
      s.prev_p = p;
      s.light_sampled = true;
      ray = {offset_origin(scene, p, ns, wi), wi};
    } else {
      const DielectricSample ds = sample_dielectric(-ray.d, n, obj.surface.ior, rng.uniform());
      if (!ds.reflected) s.inside = dot(ds.wi, n) < 0 ? hit->object : -1;
      s.light_sampled = false;
      ray = {offset_origin(scene, p, n, ds.wi), ds.wi};
    }
    if (!russian_roulette(s.beta, 1.0, depth, rng)) break;
  }
  return L;
}

}  // namespace nimbus
