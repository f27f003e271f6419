#include "nimbus/scene/compile.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <map>
#include <memory>
#include <stdexcept>
#include <tuple>

#include "nimbus/frep/bounds.h"
#include "nimbus/media/build_monitor.h"
#include "nimbus/media/medium_field.h"
#include "nimbus/media/octree.h"
#include "nimbus/render/emitter.h"
#include "nimbus/render/manifold.h"
#include "nimbus/render/microfacet_albedo.h"
#include "nimbus/scene/load.h"
#include "nimbus/spectral/wavelengths.h"

namespace nimbus {

Camera compile_camera(const CameraDesc& c, const RenderSettings& film) {
  if (c.type == CameraDesc::Type::Orthographic)
    return orthographic_camera(c.from, c.to, c.up, c.width, film.width, film.height);
  return perspective_camera(c.from, c.to, c.up, c.fov, film.width, film.height);
}

namespace {

// A texture's pattern, made once for an object and its copies.
Texture compile_texture(const TextureDesc& d, std::vector<InputFile>& inputs) {
  Texture t;
  if (d) {
    t.pattern = d.make(inputs);
    t.scale = d.scale;
  }
  return t;
}

// The surface's textures (albedo, roughness), made before its copies.
struct SurfaceTextures {
  Texture albedo, roughness;
};

Surface compile_surface(const SurfaceDesc& d, const SurfaceTextures& t) {
  Surface s;
  s.type = d.type;
  s.albedo = d.albedo;
  s.ior = d.ior;
  s.radiance = d.radiance;
  s.roughness = d.roughness;
  s.multiple_scattering = d.multiple_scattering;
  s.eta = d.eta;
  s.k = d.k;
  s.albedo_texture = t.albedo;
  s.albedo_to = d.albedo_to;
  s.roughness_texture = t.roughness;
  s.roughness_to = d.roughness_to;
  return s;
}

// The albedo tables of the rough surfaces that compensate multiple scattering, one per distinct
// surface (copies of an object, and objects alike, share one).
void tabulate_microfacet_albedo(Scene& scene) {
  std::map<std::tuple<int, double, double, double>, std::shared_ptr<const MicrofacetAlbedoLevels>>
      made;
  for (SceneObject& obj : scene.objects) {
    const Surface& s = obj.surface;
    if (!(s.roughness > 0) || !s.multiple_scattering) continue;
    const double to = s.roughness_texture ? s.roughness_to : s.roughness;
    auto& table = made[{static_cast<int>(s.type), s.roughness, to, s.ior}];
    if (!table) table = std::make_shared<const MicrofacetAlbedoLevels>(microfacet_albedo_levels(s));
    obj.albedo = table;
  }
}

Medium compile_medium(const MediumDesc& d, std::vector<InputFile>& inputs) {
  Medium m;
  m.sigma_a = d.sigma_a;
  m.sigma_s = d.sigma_s;
  m.sigma_a_texture = compile_texture(d.sigma_a_texture, inputs);
  m.sigma_s_texture = compile_texture(d.sigma_s_texture, inputs);
  m.sigma_a_to = d.sigma_a_to;
  m.sigma_s_to = d.sigma_s_to;
  m.emission = d.emission;
  if (d.emission_grid) m.emission_grid = d.emission_grid(inputs);
  m.j = d.j;
  if (d.j_grid) m.j_grid = d.j_grid(inputs);
  m.g = d.phase.type == PhaseDesc::Type::HenyeyGreenstein ? d.phase.g : 0.0;
  m.density = d.density(inputs);
  m.scale = d.density_scale;
  return m;
}

// An upper bound on the optical thickness of an object's medium across its bounds: the largest
// sigma_t at any channel or wavelength, times the density's bound there, times the bounds'
// diagonal. Tracking takes about this many steps along a ray through the object.
double optical_thickness_bound(const Scene& scene, const SceneObject& obj) {
  const Medium& m = scene.media[obj.medium];
  const Interval density = m.density->range(obj.bounds, evaluate(obj.tape, obj.bounds));
  // A textured coefficient at the larger of its ends.
  auto largest = [&](const SpectralParam& from, const SpectralParam& to, const Texture& t) {
    if (scene.settings.spectral.mode != SpectralSettings::Mode::Spectral)
      return t ? std::max(from.rgb.max_abs(), to.rgb.max_abs()) : from.rgb.max_abs();
    const double a = from.curve->range(kLambdaMin, kLambdaMax).second;
    return t ? std::max(a, to.curve->range(kLambdaMin, kLambdaMax).second) : a;
  };
  const double sigma_t = largest(m.sigma_a, m.sigma_a_to, m.sigma_a_texture) +
                         largest(m.sigma_s, m.sigma_s_to, m.sigma_s_texture);
  return m.scale * density.hi * sigma_t * length(obj.bounds.extent());
}

// An upper bound on the null collisions along a ray across an object, what tracking costs where
// the optical thickness itself is large: the largest null rate of the object's majorant octree
// (the largest majorant of any bin, the walk's scale included, minus the smallest minorant, over
// every non-empty leaf; rgb trackers take the largest channel's rate), times the bounds'
// diagonal. Real collisions end a path (absorption, max_depth) and a shadow ray (its first
// lookup through a homogeneous medium), so a gray medium of any density costs little.
double null_thickness_bound(const Scene& scene, size_t object) {
  const SceneObject& obj = scene.objects[object];
  const MajorantOctree& tree =
      obj.surface.type == Surface::Type::None ? scene.field_octree : scene.solid_octrees.at(object);
  double rate = 0;
  for (size_t i = 0; i < tree.nodes.size(); ++i) {
    if (tree.nodes[i].children >= 0 || tree.nodes[i].empty) continue;
    const double* hi = tree.mu_bar(i);
    const double* lo = tree.mu_c(i);
    const double top = *std::max_element(hi, hi + tree.bins) * std::max(1.0, tree.majorant_scale);
    rate = std::max(rate, top - *std::min_element(lo, lo + tree.bins));
  }
  return rate * length(obj.bounds.extent());
}

}  // namespace

int compiled_medium(const ObjectDesc& o) {
  return o.surface.type == Surface::Type::Diffuse || o.surface.type == Surface::Type::Emissive
             ? -1
             : o.medium;
}

Scene compile_scene(const SceneDesc& desc, const BuildMonitor& monitor,
                    std::vector<InputFile>* inputs) {
  std::vector<InputFile> read;
  Scene scene;
  scene.settings = desc.settings;
  scene.camera = compile_camera(desc.camera, desc.settings);

  for (const MediumDesc& md : desc.media) scene.media.push_back(compile_medium(md, read));
  std::vector<SurfaceTextures> textures(desc.objects.size());
  for (size_t k = 0; k < desc.objects.size(); ++k) {
    textures[k].albedo = compile_texture(desc.objects[k].surface.albedo_texture, read);
    textures[k].roughness = compile_texture(desc.objects[k].surface.roughness_texture, read);
  }
  if (inputs) {
    *inputs = desc.inputs;
    inputs->insert(inputs->end(), read.begin(), read.end());
  }

  // Each object stands for its copies (its instances, or itself once). Their tapes and bounds
  // compile in parallel: first the shapes of objects with instances, unplaced, whose bounds the
  // search finds once (a free form's take about 1.5 ms), then every copy, placed by transforming
  // only the coefficients. The rest follows in the objects' order: a scene compiles to the same
  // objects, and fails with the same first error, whatever the number of threads.
  std::vector<std::size_t> first(desc.objects.size() + 1, 0);  // each object's first copy
  for (std::size_t k = 0; k < desc.objects.size(); ++k)
    first[k + 1] = first[k] + desc.objects[k].copies();
  const std::size_t copies = first.back();
  const auto use = [&](const ObjectDesc& od) {
    const int medium = compiled_medium(od);
    return medium >= 0 && scene.media[medium].density->uses_F() ? FUse::Value : FUse::Sign;
  };
  const BuildMonitor objects_monitor{monitor.objects, monitor.cancel, nullptr};
  BuildWatch watch(objects_monitor);  // a cancel (Ctrl-C) stops this part too
  std::vector<Tape> unplaced(desc.objects.size());
  std::vector<std::exception_ptr> failed(copies);
  tbb::parallel_for(std::size_t{0}, desc.objects.size(), [&](std::size_t k) {
    const ObjectDesc& od = desc.objects[k];
    if (!od.instances || watch.cancelled()) return;
    try {
      unplaced[k] = compile(*od.shape, use(od));
    } catch (...) {
      failed[first[k]] = std::current_exception();
    }
  });
  std::vector<Tape> tapes(copies);
  std::atomic<std::size_t> done{0};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, copies), [&](const auto& range) {
    if (watch.cancelled()) return;
    std::size_t k =
        std::size_t(std::upper_bound(first.begin(), first.end(), range.begin()) - first.begin()) -
        1;
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      while (i >= first[k + 1]) ++k;
      const ObjectDesc& od = desc.objects[k];
      if (od.instances && failed[first[k]]) continue;
      try {
        tapes[i] = od.instances ? compile_placed(*od.shape, (*od.instances)[i - first[k]], use(od),
                                                 unplaced[k].bounds)
                                : compile(*od.shape, use(od));
      } catch (...) {
        failed[i] = std::current_exception();
      }
    }
    // The end is reported once, below: a report that finds another thread reporting is dropped.
    if (const std::size_t d = done += range.size(); d < copies)
      watch.report(double(d) / double(copies));
  });
  if (watch.cancelled()) return scene;  // not to be rendered
  watch.report(1);
  unplaced.clear();
  std::vector<double> field_g;    // the different anisotropies of index-matched media
  scene.objects.reserve(copies);  // growing it would hold two copies of 10^6 objects at once
  // Objects with an empty shape: the first few are named, the rest counted in one line.
  constexpr std::size_t kEmptyObjectWarnings = 8;
  std::size_t empty_objects = 0;
  for (std::size_t k = 0; k < desc.objects.size(); ++k) {
    const ObjectDesc& od = desc.objects[k];
    const int medium = compiled_medium(od);
    std::size_t empty = 0;  // copies whose shape is empty
    for (std::size_t i = first[k]; i < first[k + 1]; ++i) {
      if (failed[i]) std::rethrow_exception(failed[i]);
      SceneObject obj;
      obj.tape = std::move(tapes[i]);
      const Bounds& b = obj.tape.bounds;  // compile() computed them
      // Transforms nested in the shape and the instance's may compose past a double's range.
      for (const Quadric& q : obj.tape.quadrics)
        if (!std::all_of(q.a.begin(), q.a.end(), [](double a) { return std::isfinite(a); }))
          throw SceneError(fmt::format(
              "{}: {}{}: the transforms placing shape \"{}\" compose beyond a double's range",
              desc.source, od.json_path,
              od.instances ? fmt::format("/instances (instance {})", i - first[k]) : "/shape",
              od.shape_name));
      if (!b.bounded)
        throw SceneError(fmt::format(
            "{}: {}/shape: shape \"{}\" is unbounded; clip it with an intersection (e.g. a box)",
            desc.source, od.json_path, od.shape_name));
      if (b.box.empty()) {  // nothing is inside: the object cannot be seen
        ++empty;
        continue;
      }
      obj.bounds = b.box;
      obj.surface = compile_surface(od.surface, textures[k]);
      obj.medium = medium;
      obj.source = int(k);
      // Textures are functions of the object's own coordinates: those before its shape's
      // top-level transform and its instance's placement.
      const bool textured = obj.surface.albedo_texture || obj.surface.roughness_texture ||
                            (medium >= 0 && (scene.media[size_t(medium)].sigma_a_texture ||
                                             scene.media[size_t(medium)].sigma_s_texture));
      if (textured) {
        const Mat4 to_scene = od.instances ? (*od.instances)[i - first[k]] * od.shape->transform
                                           : od.shape->transform;
        if (to_scene.m != Mat4::identity().m) {
          obj.texture_frame = int(scene.texture_frames.size());
          scene.texture_frames.push_back(inverse(to_scene));
        }
      }
      const double g = obj.medium >= 0 ? scene.media[obj.medium].g : 0;
      if (obj.surface.type == Surface::Type::None && obj.medium >= 0 &&
          std::find(field_g.begin(), field_g.end(), g) == field_g.end()) {
        if (field_g.size() == size_t(kMaxPhaseLobes))
          throw SceneError(fmt::format(
              "{}: {}/medium: medium \"{}\" has a {}th different phase anisotropy (g {:g}) "
              "among the index-matched (surface none) media; at most {} are supported",
              desc.source, od.json_path, desc.media[obj.medium].name, kMaxPhaseLobes + 1, g,
              kMaxPhaseLobes));
        field_g.push_back(g);
      }
      scene.objects.push_back(std::move(obj));
    }
    if (empty > 0 && ++empty_objects <= kEmptyObjectWarnings)
      scene.warnings.push_back(fmt::format(
          "{}: {}/shape: shape \"{}\" is empty (its function is positive nowhere); {} not "
          "rendered",
          desc.source, od.json_path, od.shape_name,
          od.instances ? fmt::format("its {} instances are", empty) : "the object is"));
  }
  if (empty_objects > kEmptyObjectWarnings)
    scene.warnings.push_back(
        fmt::format("{}: {} more objects whose shapes are empty are not rendered", desc.source,
                    empty_objects - kEmptyObjectWarnings));
  // Their moved-from husks (264 bytes a copy) would stay through the octrees' build.
  std::vector<Tape>().swap(tapes);
  std::vector<std::exception_ptr>().swap(failed);
  scene.lights = desc.lights;
  finish_scene(scene, monitor);
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& obj = scene.objects[i];
    if (obj.medium < 0) continue;
    // The majorant scale multiplies what tracking walks (issue 29: 10^7 on a thin medium hung).
    const double scale = std::max(1.0, scene.settings.tracking.majorant_scale);
    if (optical_thickness_bound(scene, obj) * scale <= kMaxOpticalThickness) continue;
    const double tau = null_thickness_bound(scene, i);
    if (!(tau <= kMaxOpticalThickness))
      throw SceneError(fmt::format(
          "{}: {}/medium: medium \"{}\" may cost {:.3g} null collisions along a ray across the "
          "object; at most {:.0e} are supported ({})",
          desc.source, desc.objects[size_t(obj.source)].json_path, desc.media[obj.medium].name, tau,
          kMaxOpticalThickness,
          scale > 1 ? fmt::format("integrator.majorant.scale {:g} multiplies the majorants", scale)
                    : "a heterogeneous or chromatic medium this dense, or a gray one past "
                      "about 1e17 per unit of its size, would render as if hung"));
  }
  return scene;
}

void finish_scene(Scene& scene, const BuildMonitor& monitor) {
  scene.field_objects.clear();
  scene.glowing_objects.clear();
  Box all;
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& obj = scene.objects[i];
    all = unite(all, obj.bounds);
    if (obj.surface.type == Surface::Type::None && obj.medium >= 0)
      scene.field_objects.push_back(static_cast<int>(i));
    if (obj.medium >= 0 && glows(scene.media[size_t(obj.medium)]))
      scene.glowing_objects.push_back(static_cast<int>(i));
  }
  std::vector<double> field_g;
  for (int i : scene.field_objects) {
    const double g = scene.media[scene.objects[i].medium].g;
    if (std::find(field_g.begin(), field_g.end(), g) == field_g.end()) field_g.push_back(g);
  }
  if (field_g.size() > size_t(kMaxPhaseLobes))
    throw std::invalid_argument(
        fmt::format("the index-matched media have {} different phase anisotropies g; at most {} "
                    "are supported",
                    field_g.size(), kMaxPhaseLobes));
  std::vector<Box> field_bounds;
  std::vector<GridQuadric> field_quadrics;
  for (int i : scene.field_objects) {
    field_bounds.push_back(scene.objects[i].bounds);
    field_quadrics.push_back(grid_quadric(scene.objects[i].tape, scene.objects[i].medium));
  }
  scene.field_grid = build_member_grid(field_bounds, field_quadrics);
  if (!all.empty()) scene.scale = length(all.extent());
  scene.surfaces = build_surface_index(scene.objects, scene.lights);
  complete_spectra(scene);
  tabulate_microfacet_albedo(scene);
  scene.light_tree = build_light_tree(scene.lights);  // after the spectra: powers read bin_max
  scene.dielectric_solids = has_dielectric_solid(scene);
  scene.emitters = emissive_objects(scene);
  scene.lights_at_infinity.clear();
  for (size_t i = 0; i < scene.lights.size(); ++i)
    if (at_infinity(scene.lights[i])) scene.lights_at_infinity.push_back(int(i));
  scene.film_exponent = film_exponent(brightest_emission(scene));
  build_majorant_octrees(scene, monitor);
}

}  // namespace nimbus
