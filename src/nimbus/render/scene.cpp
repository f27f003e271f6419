#include "nimbus/render/scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "nimbus/spectral/planck.h"

namespace nimbus {

namespace {

// Visits the entries of the leaves whose nodes `enter` accepts, the child `second_first` names
// first; visit(entry) returns true to stop. A root that is a leaf is a short list, visited
// without a node test: each entry's own test is the box test.
template <class Enter, class SecondFirst, class Visit>
void walk(const SurfaceIndex& index, Enter&& enter, SecondFirst&& second_first, Visit&& visit) {
  if (index.nodes.empty()) return;
  if (index.nodes[0].count > 0) {
    for (const std::uint32_t e : index.entries)
      if (visit(e)) return;
    return;
  }
  // The builder's depth is below 40 + log2(entries) (surface_index.cpp): one stack entry a level.
  std::array<std::uint32_t, 128> stack;
  int top = 0;
  std::uint32_t at = 0;
  while (true) {
    const SurfaceNode& node = index.nodes[at];
    if (enter(node)) {
      if (node.count == 0) {
        std::uint32_t first = at + 1, second = node.index;
        if (second_first(node)) std::swap(first, second);
        stack[top++] = second;
        at = first;
        continue;
      }
      for (std::uint32_t k = 0; k < node.count; ++k)
        if (visit(index.entries[node.index + k])) return;
    }
    if (top == 0) return;
    at = stack[--top];
  }
}

// Visits the surfaces whose boxes the ray meets within [0, limit], nearer subtrees first (so
// that hits lower `limit` early and cull more): visit(entry) may lower limit, or return true to
// stop. A node whose box the ray enters exactly at limit is still visited (ties, surface_index.h).
template <class Visit>
void traverse(const SurfaceIndex& index, const RaySlabs& ray, double& limit, Visit&& visit) {
  walk(
      index,
      [&](const SurfaceNode& node) {
        double t0 = 0, t1 = limit;
        return clip_ray(node.bounds, ray, t0, t1);
      },
      [&](const SurfaceNode& node) { return ray.inv[node.axis] < 0; }, visit);
}

// Where the ray meets the index's entry e (an object, or a light past the objects) within
// (0, t_max): over the object's box's part of the whole range, whatever was hit before, unless
// the box begins past `beyond` (a hit there cannot be the nearest). -1 for none: a plain double,
// since an optional rebuilt byte by byte in this loop stalled its store forwarding (10 % of a
// render of four sphere lights over a floor).
double entry_hit(const Scene& scene, std::uint32_t e, const Ray& ray, const RaySlabs& slabs,
                 double t_max, double beyond) {
  const SurfaceIndex& index = scene.surfaces;
  std::optional<double> t;
  if (e < index.objects.size()) {
    const SceneObject& obj = scene.objects[index.objects[e]];
    double t0 = 0, t1 = t_max;
    if (!clip_ray(obj.bounds, slabs, t0, t1) || t0 > beyond) return -1;
    t = first_hit(obj.tape, ray, t0, t1);
  } else {
    t = intersect_light(scene.lights[index.lights[e - index.objects.size()]], ray, 0, t_max);
  }
  return t ? *t : -1;
}

}  // namespace

std::optional<SurfaceHit> intersect(const Scene& scene, const Ray& ray, double t_max) {
  const SurfaceIndex& index = scene.surfaces;
  const RaySlabs slabs(ray);
  double best_t = t_max;
  auto best = std::numeric_limits<std::uint32_t>::max();
  traverse(index, slabs, best_t, [&](std::uint32_t e) {
    const double t = entry_hit(scene, e, ray, slabs, t_max, best_t);
    // The nearest, and among equal distances the entry listed first (surface_index.h).
    if (t >= 0 && (t < best_t || (t == best_t && e < best))) {
      best_t = t;
      best = e;
    }
    return false;
  });
  if (best == std::numeric_limits<std::uint32_t>::max()) return std::nullopt;
  const size_t objects = index.objects.size();
  return best < objects ? SurfaceHit{best_t, index.objects[best], -1}
                        : SurfaceHit{best_t, -1, index.lights[best - objects]};
}

int solid_containing(const Scene& scene, const Vec3& p) {
  const SurfaceIndex& index = scene.surfaces;
  int found = -1;
  walk(
      index, [&](const SurfaceNode& node) { return node.bounds.contains(p); },
      [](const SurfaceNode&) { return false; },
      [&](std::uint32_t e) {
        if (e >= index.objects.size()) return false;
        const int i = index.objects[e];
        const SceneObject& obj = scene.objects[size_t(i)];
        if ((found < 0 || i < found) && obj.surface.type == Surface::Type::Dielectric &&
            obj.bounds.contains(p) && evaluate(obj.tape, p) > 0)
          found = i;
        return false;
      });
  return found;
}

bool occluded(const Scene& scene, const Ray& ray, double t_max, int target_light) {
  const SurfaceIndex& index = scene.surfaces;
  const size_t objects = index.objects.size();
  const RaySlabs slabs(ray);
  bool blocked = false;
  double limit = t_max;
  traverse(index, slabs, limit, [&](std::uint32_t e) {
    if (e >= objects && index.lights[e - objects] == target_light) return false;
    blocked = entry_hit(scene, e, ray, slabs, t_max, t_max) >= 0;
    return blocked;
  });
  return blocked;
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
    BuildMonitor m{nullptr, monitor.cancel, nullptr};
    if (monitor.progress)
      m.progress = [&monitor, k, trees](double f) { monitor.progress((double(k) + f) / trees); };
    return m;
  };
  scene.field_octree = build_majorant_octree(scene, -1, part(0));
  scene.solid_octrees.of_object.assign(scene.objects.size(), -1);
  scene.solid_octrees.trees.clear();
  for (size_t k = 0; k < solids.size(); ++k) {
    if (monitor.cancel && monitor.cancel()) return;
    scene.solid_octrees.of_object[solids[k]] = static_cast<int>(k);
    scene.solid_octrees.trees.push_back(build_majorant_octree(scene, solids[k], part(k + 1)));
  }
}

double brightest_emission(const Scene& scene) {
  double b = 0;
  for (const Light& light : scene.lights) b = std::max(b, largest_value(light.emission));
  for (const SceneObject& obj : scene.objects) {
    if (obj.surface.type == Surface::Type::Emissive)
      b = std::max(b, largest_value(obj.surface.radiance));
    if (obj.medium < 0) continue;
    const Medium& m = scene.media[obj.medium];
    b = std::max(b, largest_value(m.emission));
    // The hottest temperature a grid interpolates to inside the object, from the grid's own
    // extrema (vdb_density.h).
    auto hottest = [&](const TemperatureEmission& e) {
      return e.kelvin_scale * e.kelvin->range(obj.bounds, Interval::point(1.0)).hi;
    };
    if (m.emission_grid)
      b = std::max(b, brightest_temperature_emission(*m.emission_grid, hottest(*m.emission_grid)));
    // Per unit length: at most j times the longest chord of the object's bounds.
    const double chord = length(obj.bounds.extent());
    b = std::max(b, largest_value(m.j) * chord);
    if (m.j_grid)
      b = std::max(b, brightest_temperature_emission(*m.j_grid, hottest(*m.j_grid)) * chord);
  }
  return b;
}

int depth_exponent(const Scene& scene) {
  return film_exponent(scene.scale + length(scene.camera.origin));
}

AovSet film_aovs(const RenderSettings& settings) {
  AovSet aovs = settings.aovs;
  if (settings.noise_target > 0) aovs.add(Aov::Half);
  return aovs;
}

Film make_film(const Scene& scene) {
  return Film(scene.settings.width, scene.settings.height, scene.film_exponent,
              film_aovs(scene.settings), depth_exponent(scene));
}

void complete_spectra(Scene& scene) {
  for (Medium& m : scene.media) {
    complete_spectrum(m.sigma_a, SpectralRole::Unbounded);
    complete_spectrum(m.sigma_s, SpectralRole::Unbounded);
    complete_spectrum(m.sigma_a_to, SpectralRole::Unbounded);
    complete_spectrum(m.sigma_s_to, SpectralRole::Unbounded);
    complete_spectrum(m.emission, SpectralRole::Illuminant);
    complete_spectrum(m.j, SpectralRole::Illuminant);
  }
  for (SceneObject& obj : scene.objects) {
    complete_spectrum(obj.surface.albedo, SpectralRole::Albedo);
    complete_spectrum(obj.surface.albedo_to, SpectralRole::Albedo);
    complete_spectrum(obj.surface.radiance, SpectralRole::Illuminant);
    complete_spectrum(obj.surface.eta, SpectralRole::Unbounded);
    complete_spectrum(obj.surface.k, SpectralRole::Unbounded);
  }
  for (Light& l : scene.lights) complete_spectrum(l.emission, SpectralRole::Illuminant);
}

}  // namespace nimbus
