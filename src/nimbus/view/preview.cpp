#include "nimbus/view/preview.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "nimbus/math/box.h"
#include "nimbus/media/medium_field.h"

namespace nimbus {
namespace {

// What the eye sees at a surface: its colour under a light at the eye, with a floor so that
// grazing faces stay visible. Dielectrics holding a medium show the medium's single-scattering
// albedo at the point seen (x, for textures), the colour they take on once light has wandered
// inside.
Rgb surface_colour(const Scene& scene, const SceneObject& object, const Vec3& x, double cos_eye) {
  const double shade = 0.2 + 0.8 * std::abs(cos_eye);
  const Vec3 xt = texture_point(scene, object, x);
  switch (object.surface.type) {
    case Surface::Type::Emissive:
      return object.surface.radiance.rgb;
    case Surface::Type::Diffuse:
      return textured_rgb(object.surface.albedo, object.surface.albedo_to,
                          object.surface.albedo_texture, xt, 0.0) *
             shade;
    case Surface::Type::Conductor:
      return conductor_reflectance(object.surface) * shade;
    case Surface::Type::Dielectric: {
      if (object.medium < 0) return Rgb(0.9) * shade;
      const Medium& m = scene.media[size_t(object.medium)];
      const Rgb sigma_s = textured_rgb(m.sigma_s, m.sigma_s_to, m.sigma_s_texture, xt, 0.0);
      const Rgb mu_t = textured_rgb(m.sigma_a, m.sigma_a_to, m.sigma_a_texture, xt, 0.0) + sigma_s;
      Rgb albedo(0.0);
      for (int c = 0; c < 3; ++c) albedo[c] = mu_t[c] > 0 ? sigma_s[c] / mu_t[c] : 0.0;
      return albedo * shade;
    }
    case Surface::Type::None:
      break;
  }
  return Rgb(0.0);
}

// Radiance of what a ray that leaves the scene meets: the environment lights.
Rgb background(const Scene& scene) {
  Rgb L(0.0);
  for (const int i : scene.lights_at_infinity)
    if (scene.lights[size_t(i)].type == Light::Type::Environment)
      L += scene.lights[size_t(i)].emission.rgb;
  return L;
}

Box field_bounds(const Scene& scene) {
  Box b;
  for (const int i : scene.field_objects) b = unite(b, scene.objects[size_t(i)].bounds);
  return b;
}

}  // namespace

int preview_downscale(int width, int height, int pixels) {
  int d = 1;
  while (double(width) * height > double(pixels) * d * d) ++d;
  return d;
}

Image render_preview(const Scene& scene, const PreviewOptions& options) {
  const int d = std::max(1, options.downscale);
  const int w = (scene.camera.width + d - 1) / d, h = (scene.camera.height + d - 1) / d;
  Image image{w, h, std::vector<float>(size_t(w) * h * 3)};
  const Rgb sky = background(scene);
  const Box media = field_bounds(scene);
  const int steps = std::max(1, options.steps);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const double fx = std::min((x + 0.5) * d, double(scene.camera.width));
      const double fy = std::min((y + 0.5) * d, double(scene.camera.height));
      const Ray ray = scene.camera.generate(fx, fy);
      const auto hit = intersect(scene, ray, Box::kInf);
      Rgb L = sky;
      double t_end = Box::kInf;
      if (hit) {
        t_end = hit->t;
        if (hit->light >= 0) {
          L = scene.lights[size_t(hit->light)].emission.rgb;
        } else {
          const SceneObject& object = scene.objects[size_t(hit->object)];
          const Vec3 x = ray.at(hit->t);
          const Vec3 n = outward_normal(object, x);
          L = surface_colour(scene, object, x, dot(n, ray.d));
        }
      }
      // The media in front of it, marched at the steps' midpoints: transmittance T, and per
      // step mu_a L_e plus mu_s times a unit light from everywhere (eq. 4 without shadows).
      double t0 = 0, t1 = t_end;
      if (!media.empty() && clip_ray(media, ray, t0, t1) && t1 > t0) {
        const double dt = (t1 - t0) / steps;
        Rgb T(1.0), in(0.0);
        for (int i = 0; i < steps; ++i) {
          const Vec3 p = ray.at(t0 + (i + 0.5) * dt);
          Rgb mu_a(0.0), mu_s(0.0), emitted(0.0);
          for_each_medium_at(scene, p, -1, [&](int m, double density, double F, int object) {
            const Medium& medium = scene.media[size_t(m)];
            const Vec3 pt = texture_point(scene, scene.objects[size_t(object)], p);
            const Rgb a =
                textured_rgb(medium.sigma_a, medium.sigma_a_to, medium.sigma_a_texture, pt, F);
            mu_a += a * density;
            mu_s += textured_rgb(medium.sigma_s, medium.sigma_s_to, medium.sigma_s_texture, pt, F) *
                    density;
            emitted += a * medium.emission.rgb * density;
          });
          Rgb step_T(0.0);
          for (int c = 0; c < 3; ++c) step_T[c] = std::exp(-(mu_a[c] + mu_s[c]) * dt);
          // The step's own source, as if spread evenly over it: (1 - T_step) / mu_t.
          for (int c = 0; c < 3; ++c) {
            const double mu_t = mu_a[c] + mu_s[c];
            if (mu_t > 0) in[c] += T[c] * (1 - step_T[c]) * (emitted[c] + mu_s[c]) / mu_t;
          }
          T = T * step_T;
        }
        L = L * T + in;
      }
      for (int c = 0; c < 3; ++c) image.rgb[3 * (size_t(y) * w + x) + c] = float(L[c]);
    }
  });
  return image;
}

}  // namespace nimbus
