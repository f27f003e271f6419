#pragma once
// The integrator's view of the media along a ray: where the next real collision is, and how much
// light gets through. Both walk the majorant segments of the medium field.

#include "nimbus/math/rng.h"
#include "nimbus/media/medium_field.h"
#include "nimbus/render/counters.h"
#include "nimbus/render/scene.h"

namespace nimbus {

struct MediumEvent {
  enum class Type { None, Scatter, Absorb };
  Type type = Type::None;
  double t = 0;
  MediumPoint medium;  // the coefficients at the collision
  Rgb emission{0.0};   // Absorb: the emitted radiance collected there (L_e of the mixture)
};

// Null-collision delta tracking of one channel over (0, t_max) of the ray (unit direction).
// A channel of -1 means none is chosen yet: where the ray meets a medium, one is drawn uniformly
// and returned in `channel`, and the caller reweights the path.
MediumEvent sample_collision(const Scene& scene, const Ray& ray, double t_max, int inside,
                             int& channel, Rng& rng, Counters& counters);

// Transmittance over (0, t_max), by ratio tracking, and 0 if a surface blocks the way.
Rgb transmittance(const Scene& scene, const Ray& ray, double t_max, int inside, Rng& rng,
                  Counters& counters);

}  // namespace nimbus
