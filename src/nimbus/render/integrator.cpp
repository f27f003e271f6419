#include "nimbus/render/integrator.h"

#include <cmath>
#include <limits>

#include "nimbus/media/medium_field.h"
#include "nimbus/render/sampling.h"
#include "nimbus/render/volume.h"

namespace nimbus {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kShadowShrink = 1 - 1e-7;

// What a path carries from vertex to vertex.
struct PathState {
  Rgb beta{1.0};
  int inside = -1;       // the solid (dielectric) object the path is in, or -1
  bool specular = true;  // the last vertex was the camera or a specular surface
  double prev_pdf = 0;   // solid-angle pdf with which the current direction was sampled
  Vec3 prev_p;           // where it was sampled
};

// The solid object containing p (the camera may sit inside one).
int solid_containing(const Scene& scene, const Vec3& p) {
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& obj = scene.objects[i];
    if (obj.surface.type == Surface::Type::Dielectric && obj.bounds.contains(p) &&
        evaluate(obj.tape, p) > 0)
      return static_cast<int>(i);
  }
  return -1;
}

// Light reaching p along one sample of every light (next-event estimation), times the
// scattering function `f(wi)` (cosine included for surfaces) and the transmittance through media;
// MIS with the sampling of f for lights that sampling can hit.
template <class F, class Pdf>
Rgb direct_light(const Scene& scene, const Vec3& p, const Vec3& n, bool on_surface, int inside,
                 F&& f, Pdf&& f_pdf, Rng& rng, Counters& counters) {
  Rgb L(0.0);
  for (const Light& light : scene.lights) {
    const double u1 = rng.uniform(), u2 = rng.uniform();
    const auto ls = sample_light(light, p, u1, u2);
    if (!ls) continue;
    if (on_surface && dot(ls->wi, n) <= 0) continue;
    const Rgb fv = f(ls->wi);
    if (fv.is_black()) continue;
    const Vec3 o = on_surface ? offset_origin(scene, p, n, ls->wi) : p;
    const Rgb T =
        transmittance(scene, {o, ls->wi}, ls->distance * kShadowShrink, inside, rng, counters);
    if (T.is_black()) continue;
    if (ls->delta)
      L += fv * ls->Li * T;
    else
      L += fv * ls->Li * T * (power_heuristic(ls->pdf, f_pdf(ls->wi)) / ls->pdf);
  }
  return L;
}

bool russian_roulette(PathState& s, int depth, Rng& rng) {
  if (depth < 3) return true;
  const double q = std::min(1.0, s.beta.max());
  if (q <= 0 || rng.uniform() >= q) return false;
  s.beta /= q;  // unbiased: survivors carry 1/q
  return true;
}

}  // namespace

Rgb radiance(const Scene& scene, Ray ray, Rng& rng, Counters& counters) {
  ++counters.paths;
  Rgb L(0.0);
  PathState s;
  s.prev_p = ray.o;
  s.inside = solid_containing(scene, ray.o);
  // Delta tracking follows one channel per path, chosen uniformly when the path first meets a
  // medium, and from then on carries its weight (times 3) to that channel only.
  int channel = -1;

  auto mis_weight = [&](const Light& light) {
    return s.specular ? 1.0 : power_heuristic(s.prev_pdf, light_pdf(light, s.prev_p, ray.d));
  };

  for (int depth = 0;; ++depth) {
    ++counters.surface_rays;
    const auto hit = intersect(scene, ray, kInf);
    const double t_surface = hit ? hit->t : kInf;

    const int channel_before = channel;
    const MediumEvent ev =
        sample_collision(scene, ray, t_surface, s.inside, channel, rng, counters);
    if (channel != channel_before) {
      const double b = s.beta[channel];
      s.beta = Rgb(0.0);
      s.beta[channel] = 3 * b;
    }
    if (ev.type == MediumEvent::Type::Absorb) {
      L += s.beta * ev.emission;
      break;
    }
    if (ev.type == MediumEvent::Type::Scatter) {
      if (depth >= scene.settings.max_depth) break;
      const Vec3 p = ray.at(ev.t);
      const MediumPoint& m = ev.medium;
      // A solid's boundary is specular: no shadow ray can leave it, so skip NEE inside one.
      if (s.inside < 0)
        L += s.beta * direct_light(
                          scene, p, {}, false, s.inside,
                          [&](const Vec3& wi) { return phase_value(m, dot(ray.d, wi)); },
                          [&](const Vec3& wi) { return phase_pdf(m, dot(ray.d, wi)); }, rng,
                          counters);
      Rgb weight;
      double pdf;
      const double u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
      const Vec3 wi = sample_phase(m, ray.d, u0, u1, u2, weight, pdf);
      s.beta *= weight;
      s.prev_pdf = pdf;
      s.prev_p = p;
      s.specular = false;
      ray = {p, wi};
      if (!russian_roulette(s, depth, rng)) break;
      continue;
    }

    if (!hit) {
      for (const Light& light : scene.lights)
        if (light.type == Light::Type::Environment)
          L += s.beta * light.radiance * mis_weight(light);
      break;
    }
    if (hit->light >= 0) {
      const Light& light = scene.lights[hit->light];
      L += s.beta * light.radiance * mis_weight(light);
      break;
    }
    const SceneObject& obj = scene.objects[hit->object];
    const Vec3 p = ray.at(hit->t);
    const Vec3 n = outward_normal(obj, p);
    if (obj.surface.type == Surface::Type::Emissive) {
      if (dot(ray.d, n) < 0) L += s.beta * obj.surface.radiance;
      break;
    }
    if (depth >= scene.settings.max_depth) break;

    if (obj.surface.type == Surface::Type::Diffuse) {
      const Vec3 ns = dot(ray.d, n) < 0 ? n : -n;  // facing the incoming ray
      const Rgb f = obj.surface.albedo * kInvPi;
      L += s.beta * direct_light(
                        scene, p, ns, true, s.inside,
                        [&](const Vec3& wi) { return f * dot(wi, ns); },
                        [&](const Vec3& wi) { return dot(wi, ns) * kInvPi; }, rng, counters);
      const double u1 = rng.uniform(), u2 = rng.uniform();
      const Vec3 wi = sample_cosine_hemisphere(ns, u1, u2);
      s.beta *= obj.surface.albedo;  // f cos / pdf = albedo
      s.prev_pdf = dot(wi, ns) * kInvPi;
      s.prev_p = p;
      s.specular = false;
      ray = {offset_origin(scene, p, ns, wi), wi};
    } else {
      const DielectricSample ds = sample_dielectric(-ray.d, n, obj.surface.ior, rng.uniform());
      if (!ds.reflected) s.inside = dot(ds.wi, n) < 0 ? hit->object : -1;
      s.specular = true;
      ray = {offset_origin(scene, p, n, ds.wi), ds.wi};
    }
    if (!russian_roulette(s, depth, rng)) break;
  }
  return L;
}

}  // namespace nimbus
