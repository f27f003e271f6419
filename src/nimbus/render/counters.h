#pragma once
// Per-thread event counters, merged at the end of a render and reported in --stats.

#include <cstdint>

#include "nimbus/tracking/counters.h"

namespace nimbus {

// Manifold next-event estimation (render/manifold.h).
struct ManifoldCounters {
  uint64_t walks = 0;          // chains sought by next-event estimation
  uint64_t found = 0;          // of which converged to a valid chain
  uint64_t newton_steps = 0;   // Newton iterations over all walks
  uint64_t checks = 0;         // walks repeated to decide whether a sampled path is the walk's
  uint64_t mirror_probes = 0;  // rays cast in a smooth boundary's mirror direction (mirror_light.h)

  ManifoldCounters& operator+=(const ManifoldCounters& o) {
    walks += o.walks;
    found += o.found;
    newton_steps += o.newton_steps;
    checks += o.checks;
    mirror_probes += o.mirror_probes;
    return *this;
  }
};

struct Counters {
  uint64_t paths = 0;
  uint64_t surface_rays = 0;  // closest-hit queries
  uint64_t shadow_rays = 0;
  uint64_t real_collisions = 0;    // scattering or absorption events in media
  uint64_t scatter_events = 0;     // real scattering events in media
  uint64_t majorant_segments = 0;  // segments of the majorant walk that estimators tracked over
  uint64_t rejected_samples = 0;   // NaN or infinite sample values the film refused (film.h)
  uint64_t shadow_lookups = 0;     // the shadow rays' share of tracking.lookups
  TrackingCounters tracking;       // tentative collisions, density lookups, clamped probabilities
  ManifoldCounters manifold;

  uint64_t null_collisions() const { return tracking.tentative_collisions - real_collisions; }

  Counters& operator+=(const Counters& o) {
    paths += o.paths;
    surface_rays += o.surface_rays;
    shadow_rays += o.shadow_rays;
    real_collisions += o.real_collisions;
    scatter_events += o.scatter_events;
    majorant_segments += o.majorant_segments;
    rejected_samples += o.rejected_samples;
    shadow_lookups += o.shadow_lookups;
    tracking += o.tracking;
    manifold += o.manifold;
    return *this;
  }
};

}  // namespace nimbus
