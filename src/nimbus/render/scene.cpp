#include "nimbus/render/scene.h"

#include <algorithm>
#include <cmath>

#include "nimbus/spectral/planck.h"

namespace nimbus {

SurfaceIndex build_surface_index(const std::vector<SceneObject>& objects,
                                 const std::vector<Light>& lights) {
  SurfaceIndex index;
  for (size_t i = 0; i < objects.size(); ++i)
    if (objects[i].surface.type != Surface::Type::None) index.objects.push_back(int(i));
  for (size_t i = 0; i < lights.size(); ++i)
    if (has_surface(lights[i])) index.lights.push_back(int(i));
  index.object_count = objects.size();
  index.light_count = lights.size();
  return index;
}

std::optional<SurfaceHit> intersect(const Scene& scene, const Ray& ray, double t_max) {
  std::optional<SurfaceHit> best;
  for (const int i : scene.surfaces.objects) {
    const SceneObject& obj = scene.objects[i];
    double t0 = 0, t1 = t_max;
    if (!clip_ray(obj.bounds, ray, t0, t1)) continue;
    if (auto t = first_hit(obj.tape, ray, t0, t1)) {
      t_max = *t;
      best = SurfaceHit{*t, i, -1};
    }
  }
  for (const int i : scene.surfaces.lights) {
    if (auto t = intersect_light(scene.lights[i], ray, 0, t_max)) {
      t_max = *t;
      best = SurfaceHit{*t, -1, i};
    }
  }
  return best;
}

bool occluded(const Scene& scene, const Ray& ray, double t_max, int target_light) {
  for (const int i : scene.surfaces.objects) {
    const SceneObject& obj = scene.objects[i];
    double t0 = 0, t1 = t_max;
    if (!clip_ray(obj.bounds, ray, t0, t1)) continue;
    if (first_hit(obj.tape, ray, t0, t1)) return true;
  }
  for (const int i : scene.surfaces.lights)
    if (i != target_light && intersect_light(scene.lights[i], ray, 0, t_max)) return true;
  return false;
}

Vec3 outward_normal(const SceneObject& object, const Vec3& p) {
  return normalize(-gradient(object.tape, p));
}

Vec3 offset_origin(const Scene& scene, const Vec3& p, const Vec3& n, const Vec3& w) {
  const double eps =
      1e-7 * std::max({1.0, scene.scale, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  return dot(n, w) >= 0 ? p + n * eps : p - n * eps;
}

OctreeSettings octree_settings(const RenderSettings& settings) {
  const TrackingSettings& t = settings.tracking;
  return {t.octree_depth,     t.majorant_source == TrackingSettings::MajorantSource::Sample,
          t.majorant_samples, t.majorant_scale,
          settings.seed,      settings.spectral.mode == SpectralSettings::Mode::Spectral};
}

MajorantOctree build_majorant_octree(const Scene& scene, int inside, const BuildMonitor& monitor) {
  std::vector<OctreeMember> members;
  auto add = [&](int i) {
    const SceneObject& obj = scene.objects[i];
    if (obj.medium >= 0) members.push_back({&obj.tape, obj.bounds, obj.medium});
  };
  if (inside >= 0) {
    add(inside);
  } else {
    for (int i : scene.field_objects) add(i);
  }
  return build_majorant_octree(scene.media, members, inside >= 0, octree_settings(scene.settings),
                               monitor);
}

void build_majorant_octrees(Scene& scene, const BuildMonitor& monitor) {
  std::vector<int> solids;
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& obj = scene.objects[i];
    if (has_own_octree(obj.medium, obj.surface.type)) solids.push_back(static_cast<int>(i));
  }
  // Each tree gets an equal share of the progress: their costs are not known in advance.
  const double trees = double(solids.size() + 1);
  auto part = [&](size_t k) {
    BuildMonitor m{nullptr, monitor.cancel};
    if (monitor.progress)
      m.progress = [&monitor, k, trees](double f) { monitor.progress((double(k) + f) / trees); };
    return m;
  };
  scene.field_octree = build_majorant_octree(scene, -1, part(0));
  scene.solid_octrees.assign(scene.objects.size(), MajorantOctree{});
  for (size_t k = 0; k < solids.size(); ++k) {
    if (monitor.cancel && monitor.cancel()) return;
    scene.solid_octrees[solids[k]] = build_majorant_octree(scene, solids[k], part(k + 1));
  }
}

namespace {

// The largest value of an emitted colour in rgb mode (a channel) or spectral mode (a bin's bound).
double largest(const SpectralParam& p) {
  double m = p.rgb.max();
  for (double b : p.bin_max) m = std::max(m, b);
  return m;
}

}  // namespace

double brightest_emission(const Scene& scene) {
  double b = 0;
  for (const Light& light : scene.lights) b = std::max(b, largest(light.emission));
  for (const SceneObject& obj : scene.objects) {
    if (obj.surface.type == Surface::Type::Emissive) b = std::max(b, largest(obj.surface.radiance));
    if (obj.medium < 0) continue;
    const Medium& m = scene.media[obj.medium];
    b = std::max(b, largest(m.emission));
    if (m.emission_grid) {
      // The hottest temperature the grid interpolates to inside the object, from the grid's own
      // extrema (vdb_density.h); B's peak and its rgb both grow with the temperature.
      const double kelvin = m.emission_grid->kelvin->range(obj.bounds, Interval::point(1.0)).hi;
      if (kelvin >= kMinEmittingKelvin)
        b = std::max(b, m.emission_grid->scale *
                            std::max(planck_rgb(kelvin).max(), planck_spectrum(kelvin).scale));
    }
  }
  return b;
}

Film make_film(const Scene& scene) {
  return Film(scene.settings.width, scene.settings.height, scene.film_exponent);
}

void complete_spectra(Scene& scene) {
  for (Medium& m : scene.media) {
    complete_spectrum(m.sigma_a, SpectralRole::Unbounded);
    complete_spectrum(m.sigma_s, SpectralRole::Unbounded);
    complete_spectrum(m.emission, SpectralRole::Illuminant);
  }
  for (SceneObject& obj : scene.objects) {
    complete_spectrum(obj.surface.albedo, SpectralRole::Albedo);
    complete_spectrum(obj.surface.radiance, SpectralRole::Illuminant);
  }
  for (Light& l : scene.lights) complete_spectrum(l.emission, SpectralRole::Illuminant);
}

}  // namespace nimbus
