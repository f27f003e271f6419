#pragma once
// Records a camera path's FirstVertex (render/aov.h) as trace_path meets things. Depth is where
// the camera ray ends; albedo and normal are those of the first vertex that is not a perfect
// specular surface, which OIDN prefers to the specular surface's own: through a dielectric, the
// reflected or refracted path's next vertex, chosen by the path's own Fresnel choice, so that the
// pixel's average is their Fresnel blend. Until then (a path that ends on a chain of dielectric
// surfaces) the first dielectric's normal and albedo 1 stand.

#include "nimbus/math/ray.h"
#include "nimbus/math/vec3.h"
#include "nimbus/render/aov.h"
#include "nimbus/render/light.h"
#include "nimbus/render/material.h"
#include "nimbus/render/scene.h"

namespace nimbus {

class FirstVertexRecorder {
 public:
  // Records into `out`; with none, every call costs a test of one flag.
  explicit FirstVertexRecorder(FirstVertex* out) : out_(out), pending_(out != nullptr) {}

  // A real collision (scattering or absorption) in a medium at distance t, seen from the solid
  // `inside` (-1: the field): the single-scattering albedo of the media's RGB coefficients there
  // (in spectral mode too), normal -ray.d.
  void medium(const Scene& scene, const Ray& ray, double t, int inside) {
    if (pending_) record_medium(scene, ray, t, inside);
  }

  // An object's surface at distance t, of outward normal n: a diffuse surface's reflectance, a
  // conductor's at normal incidence, an emissive surface's 0, the normal facing the ray; a
  // dielectric is passed through.
  void surface(const Scene& scene, const SceneObject& object, const Ray& ray, double t,
               const Vec3& n) {
    if (!pending_) return;
    const Surface& s = object.surface;
    const Vec3 facing = dot(ray.d, n) < 0 ? n : -n;
    if (s.type == Surface::Type::Dielectric) {
      if (camera_ray_) set(Rgb(1.0), facing);
      camera_ray_ends(t);
      return;
    }
    camera_ray_ends(t);
    set(s.type == Surface::Type::Diffuse
            ? textured_rgb(s.albedo, s.albedo_to, s.albedo_texture,
                           texture_point(scene, object, ray.at(t)), 0.0)
        : s.type == Surface::Type::Conductor ? conductor_reflectance(s)
                                             : Rgb(0.0),
        facing);
    pending_ = false;
  }

  // A sphere light's surface at distance t: albedo 0, its normal.
  void light(const Light& l, const Ray& ray, double t) {
    if (!pending_) return;
    camera_ray_ends(t);
    set(Rgb(0.0), normalize(ray.at(t) - l.center));
    pending_ = false;
  }

  // The ray left the scene: albedo 0, normal 0.
  void escape() {
    if (!pending_) return;
    set(Rgb(0.0), Vec3{});
    pending_ = false;
  }

 private:
  void record_medium(const Scene& scene, const Ray& ray, double t, int inside);
  void camera_ray_ends(double t) {
    if (camera_ray_) out_->depth = t;
    camera_ray_ = false;
  }
  void set(const Rgb& albedo, const Vec3& normal) {
    out_->albedo = albedo;
    out_->normal = normal;
  }

  FirstVertex* out_;
  bool pending_;            // albedo and normal may still change
  bool camera_ray_ = true;  // nothing met yet: the ray is the camera's
};

}  // namespace nimbus
