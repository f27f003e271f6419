#pragma once
// The integrator's view of the media along a ray: where the next real collision is, and how much
// light gets through. Both walk the majorant segments of the medium field with the estimators of
// tracking/ that the scene's tracking settings select (docs/media.md).

#include "nimbus/math/rng.h"
#include "nimbus/media/medium_field.h"
#include "nimbus/render/counters.h"
#include "nimbus/render/scene.h"
#include "nimbus/tracking/spectral_mis.h"

namespace nimbus {

struct MediumEvent {
  enum class Type { None, Scatter, Absorb };
  Type type = Type::None;
  double t = 0;
  MediumPoint medium;  // the coefficients at the collision
  Rgb emitted{0.0};    // radiance emitted by the media on the way, already weighted by the path
};

// The next real collision over (0, t_max) of the ray (unit direction), for every mode but
// spectral-mis. `beta`, the path throughput, is updated by the tracking weights.
// delta: one channel per path; `channel` -1 means none is chosen yet: where the ray meets a
// medium one is drawn uniformly and returned, and beta keeps that channel only (times 3).
// spectral-max, spectral-history: every channel along one free path; `channel` is unused.
MediumEvent sample_collision(const Scene& scene, const Ray& ray, double t_max, int inside,
                             Rgb& beta, int& channel, Rng& rng, Counters& counters);

// spectral-mis: the next real collision with hero channel `hero`, updating beta, r_u and r_l.
MediumEvent sample_collision_mis(const Scene& scene, const Ray& ray, double t_max, int inside,
                                 int hero, MisPath<3>& path, Rng& rng, Counters& counters);

// Transmittance over (0, t_max) by ratio or residual ratio tracking (settings.transmittance),
// and 0 if a surface blocks the way. `light` is the light the shadow ray aims at (it does not
// block), or -1.
Rgb transmittance(const Scene& scene, const Ray& ray, double t_max, int light, int inside, Rng& rng,
                  Counters& counters);

// spectral-mis: the shadow ray's T_ray, r_u and r_l (in `path`, which starts at 1), by hero ratio
// tracking. False if a surface blocks the way or T_ray became 0.
bool transmittance_mis(const Scene& scene, const Ray& ray, double t_max, int light, int inside,
                       int hero, MisPath<3>& path, Rng& rng, Counters& counters);

}  // namespace nimbus
