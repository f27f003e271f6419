#pragma once
// Points on emissive surfaces, for manifold next-event estimation through smooth boundaries
// (render/manifold_light.h): the walk needs a point on the light, with its density per unit area.
// A surface is sampled from its bounds' centre c: a direction u uniform on the sphere, then one
// of the k roots of F along the ray c + t u, uniformly. Every point y of the surface lies on the
// ray through it, so the density is positive wherever n · u ≠ 0 and known exactly:
//   pdf_A(y) = |n · u| / (4π |y − c|² k(u)),   u = (y − c) / |y − c|.
// It is uniform in area on a sphere about c; on other shapes it varies with the angle between
// the normal and u (and is large on surfaces seen edge-on from c, where no sample falls).

#include <optional>

#include "nimbus/math/vec3.h"
#include "nimbus/render/scene.h"

namespace nimbus {

// Most roots of F along one ray from the centre; a ray with more has none sampled (and a path
// that reaches one of them is left to BSDF and phase sampling, render/manifold_light.h).
inline constexpr int kMaxEmitterRoots = 16;

struct EmitterPoint {
  Vec3 y;
  Vec3 n;  // outward normal
  double pdf_area = 0;
};

// A point on object `object`'s surface from u1, u2 (the direction) and u3 (the root); none where
// the ray from the centre meets no root, or more than kMaxEmitterRoots.
std::optional<EmitterPoint> sample_emitter_point(const Scene& scene, int object, double u1,
                                                 double u2, double u3);

// The density per unit area with which sample_emitter_point picks y, a point on the surface with
// outward normal n: 0 where it never does.
double emitter_point_pdf(const Scene& scene, int object, const Vec3& y, const Vec3& n);

// The solid-angle density with which next-event estimation at p picks y on emissive object
// `object` (outward normal n there): one of the scene's emitters picked uniformly, then
// sample_emitter_point; 0 where y faces away from p.
double emitter_solid_angle_pdf(const Scene& scene, int object, const Vec3& p, const Vec3& y,
                               const Vec3& n);

// The objects with emissive surfaces that the walk targets, in object order (finish_scene).
std::vector<int> emissive_objects(const Scene& scene);

}  // namespace nimbus
