#pragma once
// The medium as a field (DESIGN.md): wherever an index-matched object's function is positive its
// medium is present, and overlapping media add. Inside a solid object (a dielectric with a
// medium) only that object's medium is present: a solid displaces the media around it.

#include <array>
#include <utility>
#include <vector>

#include "nimbus/math/ray.h"
#include "nimbus/media/medium.h"
#include "nimbus/media/octree.h"
#include "nimbus/render/scene.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

// The coefficients at a point, with the phase function of the mixture of media present there.
struct MediumPoint {
  static constexpr int kMaxMedia = 8;
  Rgb mu_a{0.0}, mu_s{0.0};
  Rgb mu_a_Le{0.0};  // Σ mu_a,i L_e,i
  int media = 0;     // how many media contribute
  std::array<double, kMaxMedia> g{};
  std::array<Rgb, kMaxMedia> mu_s_i{};  // each medium's scattering coefficient
  Rgb mu_t() const { return mu_a + mu_s; }
};

// `inside` is the solid object the point is in (-1: none).
MediumPoint medium_at(const Scene& scene, const Vec3& x, int inside);

// A stretch of a ray with a majorant mu_bar and a minorant mu_c of mu_t there, per channel.
// mu_bar is multiplied by the scene's majorant scale, so it need not bound when that is < 1.
struct MajorantSegment {
  double t0, t1;
  Rgb mu_bar;
  Rgb mu_c{0.0};
};

// Calls f(const MajorantSegment&) for the majorant segments covering the media along the ray in
// [t_min, t_max], in order, from the leaves of the scene's majorant octree (octree.h) for
// `inside` (-1: the field; else that solid object). Where no medium can be there is a gap;
// neighbouring leaves with identical bounds become one segment. f returns false to stop the
// walk. The ray direction must be unit length.
template <class F>
void walk_majorant_segments(const Scene& scene, const Ray& ray, double t_min, double t_max,
                            int inside, F&& f) {
  if (inside >= 0 && scene.objects[inside].medium < 0) return;  // a solid without a medium
  // at(): a scene whose octrees were never built fails loudly rather than reading past the end.
  const MajorantOctree& tree = inside >= 0 ? scene.solid_octrees.at(inside) : scene.field_octree;
  const double scale = scene.settings.tracking.majorant_scale;
  MajorantSegment pending{0, 0, Rgb(0.0), Rgb(0.0)};
  bool has_pending = false;
  const bool finished =
      walk_octree(tree, ray, t_min, t_max, [&](const OctreeNode& node, double a, double b) {
        const Rgb mu_bar = node.mu_bar * scale;
        if (has_pending && a == pending.t1 && mu_bar == pending.mu_bar &&
            node.mu_c == pending.mu_c) {
          pending.t1 = b;
          return true;
        }
        if (has_pending && !f(std::as_const(pending))) return false;
        pending = {a, b, mu_bar, node.mu_c};
        has_pending = true;
        return true;
      });
  if (finished && has_pending) f(std::as_const(pending));
}

// The mixture phase function at a scattering point: value per channel and its sampling.
Rgb phase_value(const MediumPoint& m, double cos_theta);
// Picks a medium with probability ∝ its average mu_s, then samples its HG lobe; returns the
// direction and the per-channel weight phase_value / pdf (exactly 1 for a single medium).
Vec3 sample_phase(const MediumPoint& m, const Vec3& dir, double u0, double u1, double u2,
                  Rgb& weight, double& pdf);
double phase_pdf(const MediumPoint& m, double cos_theta);

}  // namespace nimbus
