#include "nimbus/view/preview_mesh.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <numbers>
#include <string_view>
#include <unordered_map>

#include "nimbus/mesh/polygonize.h"

namespace nimbus {
namespace {

// A medium's single-scattering albedo σ_s / (σ_a + σ_s), as its colour.
Rgb medium_colour(const Medium& m) {
  Rgb c;
  for (int i = 0; i < 3; ++i) {
    const double t = m.sigma_a.rgb[i] + m.sigma_s.rgb[i];
    c[i] = t > 0 ? m.sigma_s.rgb[i] / t : 0;
  }
  return c;
}

// A conductor's reflectance at normal incidence: ((η − 1)² + k²) / ((η + 1)² + k²).
Rgb conductor_colour(const Surface& s) {
  Rgb c;
  for (int i = 0; i < 3; ++i) {
    const double eta = s.eta.rgb[i], k = s.k.rgb[i];
    c[i] = ((eta - 1) * (eta - 1) + k * k) / ((eta + 1) * (eta + 1) + k * k);
  }
  return c;
}

// A medium's hull's opacity: 1 − exp(−σ_t L) across L, half the object's largest extent, at the
// density's scale; at least faint, so that thin media show where they are, and at most half.
double hull_opacity(const Medium& m, const Box& bounds) {
  const Vec3 e = bounds.extent();
  const double length = 0.5 * std::max({e.x, e.y, e.z});
  const double sigma_t = (m.sigma_a.rgb + m.sigma_s.rgb).max() * m.scale;
  return std::clamp(1 - std::exp(-sigma_t * length), 0.02, 0.5);
}

// A sphere as latitude-longitude bands: a light bulb in the preview.
std::shared_ptr<const TriangleMesh> sphere_mesh(const Vec3& centre, double radius) {
  constexpr int kBands = 6, kSegments = 12;
  auto m = std::make_shared<TriangleMesh>();
  for (int i = 0; i <= kBands; ++i)
    for (int j = 0; j < kSegments; ++j) {
      const double theta = std::numbers::pi * i / kBands,
                   phi = 2 * std::numbers::pi * j / kSegments;
      const Vec3 n{std::sin(theta) * std::cos(phi), std::cos(theta),
                   std::sin(theta) * std::sin(phi)};
      m->positions.push_back(centre + radius * n);
      m->normals.push_back(n);
    }
  const auto at = [](int i, int j) { return std::uint32_t(i * kSegments + j % kSegments); };
  for (int i = 0; i < kBands; ++i)
    for (int j = 0; j < kSegments; ++j) {
      // Counter-clockwise seen from outside.
      m->triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j)});
      m->triangles.push_back({at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)});
    }
  return m;
}

void put_u32(std::string& out, std::uint32_t v) {
  char bytes[4];
  std::memcpy(bytes, &v, 4);  // little-endian machines only, as the rest of the file formats
  out.append(bytes, 4);
}
void put_f32(std::string& out, double v) {
  const float f = float(v);
  char bytes[4];
  std::memcpy(bytes, &f, 4);
  out.append(bytes, 4);
}
void put_vec(std::string& out, const Vec3& v) {
  for (int k = 0; k < 3; ++k) put_f32(out, v[k]);
}

template <class T>
void put_raw(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

}  // namespace

PreviewScene preview_scene(const Scene& scene) {
  PreviewScene out;
  for (const Light& l : scene.lights)
    if (l.type == Light::Type::Environment) out.background += l.emission.rgb;
  for (const SceneObject& obj : scene.objects) {
    const Surface& s = obj.surface;
    const Medium* m = obj.medium >= 0 ? &scene.media[size_t(obj.medium)] : nullptr;
    PreviewObject p;
    p.tape = obj.tape;
    switch (s.type) {
      case Surface::Type::Diffuse:
        p.colour = s.albedo_texture ? 0.5 * (s.albedo.rgb + s.albedo_to.rgb) : s.albedo.rgb;
        break;
      case Surface::Type::Conductor:
        p.colour = conductor_colour(s);
        break;
      case Surface::Type::Emissive:
        p.colour = s.radiance.rgb.max() > 0 ? s.radiance.rgb / s.radiance.rgb.max() : Rgb(0.0);
        break;
      case Surface::Type::Dielectric:
        // A translucent object shows its medium; clear glass is drawn see-through.
        if (m) {
          p.colour = medium_colour(*m);
        } else {
          p.colour = Rgb(0.85);
          p.opacity = 0.3;
        }
        break;
      case Surface::Type::None:
        if (!m) continue;  // neither a surface nor a medium: nothing to see
        p.colour = medium_colour(*m);
        p.opacity = hull_opacity(*m, obj.bounds);
        break;
    }
    out.objects.push_back(std::move(p));
  }
  for (const Light& l : scene.lights) {
    if (l.type != Light::Type::Sphere || !(l.radius > 0)) continue;
    PreviewObject p;
    p.mesh = sphere_mesh(l.center, l.radius);
    const double peak = l.emission.rgb.max();
    p.colour = peak > 0 ? l.emission.rgb / peak : Rgb(0.0);
    out.objects.push_back(std::move(p));
  }
  return out;
}

std::string tape_key(const Tape& tape) {
  std::string key;
  put_raw(key, tape.quadrics.size());
  for (const Quadric& q : tape.quadrics)
    for (double a : q.a) put_raw(key, a);
  // Field by field: an Instr's padding is not part of it.
  for (const Instr& i : tape.code) {
    put_raw(key, i.op);
    put_raw(key, i.dst);
    put_raw(key, i.src);
    put_raw(key, i.quadric);
    put_raw(key, i.weight);
  }
  for (double w : tape.weights) put_raw(key, w);
  return key;
}

std::string PreviewMesher::update(const PreviewScene& scene, PreviewMeshStats* stats) {
  PreviewMeshStats st;
  const size_t n = scene.objects.size();
  std::vector<std::string> keys(n);
  std::vector<std::shared_ptr<const TriangleMesh>> meshes(n);
  std::vector<std::uint8_t> fresh(n, 0);
  const auto largest_extent = [](const Box& b) {
    const Vec3 e = b.extent();
    return std::max({e.x, e.y, e.z});
  };
  Box everything;  // empty
  for (const PreviewObject& o : scene.objects)
    if (o.tape.bounds.bounded && !o.tape.bounds.box.empty())
      everything = unite(everything, o.tape.bounds.box);
  const double scene_size = everything.empty() ? 0 : largest_extent(everything);
  const double floor =
      scene_size > 0 ? std::exp2(std::round(std::log2(options_.scene_error * scene_size))) : 0;
  std::vector<double> error(n);
  for (size_t i = 0; i < n; ++i) {
    if (scene.objects[i].mesh) continue;
    const Tape& tape = scene.objects[i].tape;
    error[i] = std::max(options_.relative_error * largest_extent(tape.bounds.box), floor);
    // A medium's hull is seen through, its edge soft: four times coarser.
    if (scene.objects[i].opacity < 1) error[i] *= 4;
    keys[i] = tape_key(tape);
    put_raw(keys[i], error[i]);
    const auto found = meshes_.find(keys[i]);
    if (found != meshes_.end()) meshes[i] = found->second;
  }
  // Copies of one object (the same function, placed the same) share a key and are meshed once,
  // by the first.
  std::unordered_map<std::string_view, size_t> first_of;
  for (size_t i = 0; i < n; ++i)
    if (!scene.objects[i].mesh) first_of.try_emplace(keys[i], i);
  // The objects met for the first time, meshed side by side (each mesh is the same for any
  // number of threads), until the meshes pass the page's budget of triangles: a scene of many
  // thousand objects shows the first of them.
  std::atomic<std::uint64_t> triangles{0};
  for (const auto& m : meshes)
    if (m) triangles += m->triangles.size();
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    if (meshes[i] || scene.objects[i].mesh || first_of.at(keys[i]) != i) return;
    if (triangles.load(std::memory_order_relaxed) > options_.max_triangles) return;
    const Tape& tape = scene.objects[i].tape;
    if (!tape.bounds.bounded || tape.bounds.box.empty()) return;
    PolygonizeOptions po;
    po.error = error[i];
    po.max_cells = options_.max_cells;
    po.first_cells = 4;  // refined as far as the error asks, and no further
    // An object too fine for the budget at this error is meshed coarser: a preview, not an export.
    for (int attempt = 0; attempt < 4; ++attempt, po.error *= 4) {
      try {
        meshes[i] = std::make_shared<const TriangleMesh>(polygonize(tape, po));
        fresh[i] = 1;
        triangles += meshes[i]->triangles.size();
        return;
      } catch (const PolygonizeError&) {
      }
    }
  });
  std::map<std::string, std::shared_ptr<const TriangleMesh>> kept;
  for (size_t i = 0; i < n; ++i) {
    if (scene.objects[i].mesh) {
      meshes[i] = scene.objects[i].mesh;
      ++st.given;
      st.triangles += meshes[i]->triangles.size();
      continue;
    }
    if (!meshes[i]) meshes[i] = meshes[first_of.at(keys[i])];
    if (!meshes[i]) {
      ++st.skipped;
      continue;
    }
    (fresh[i] ? st.meshed : st.reused) += 1;
    st.triangles += meshes[i]->triangles.size();
    kept.emplace(keys[i], meshes[i]);
  }
  meshes_ = std::move(kept);
  if (stats) *stats = st;
  return encode_preview_meshes(scene, meshes);
}

std::string encode_preview_meshes(const PreviewScene& scene,
                                  const std::vector<std::shared_ptr<const TriangleMesh>>& meshes) {
  Box bounds;  // empty
  std::uint32_t count = 0;
  for (const auto& m : meshes) {
    if (!m) continue;
    ++count;
    for (const Vec3& p : m->positions) bounds = unite(bounds, Box{p, p});
  }
  std::string out = "NMSH";
  put_u32(out, 1);
  put_u32(out, count);
  put_vec(out, Vec3{scene.background[0], scene.background[1], scene.background[2]});
  put_vec(out, count ? bounds.lo : Vec3{0, 0, 0});
  put_vec(out, count ? bounds.hi : Vec3{0, 0, 0});
  for (size_t i = 0; i < meshes.size(); ++i) {
    if (!meshes[i]) continue;
    const PreviewObject& o = scene.objects[i];
    const TriangleMesh& m = *meshes[i];
    put_vec(out, Vec3{o.colour[0], o.colour[1], o.colour[2]});
    put_f32(out, o.opacity);
    put_u32(out, std::uint32_t(m.positions.size()));
    put_u32(out, std::uint32_t(m.triangles.size()));
    for (const Vec3& p : m.positions) put_vec(out, p);
    for (const Vec3& v : m.normals) put_vec(out, v);
    for (const auto& t : m.triangles)
      for (std::uint32_t v : t) put_u32(out, v);
  }
  return out;
}

}  // namespace nimbus
