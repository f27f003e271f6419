#pragma once
// Work counters of the tracking estimators, kept by the caller (one per thread) and merged.

#include <cstdint>

namespace nimbus {

struct TrackingCounters {
  uint64_t lookups = 0;               // calls of the medium lookup
  uint64_t tentative_collisions = 0;  // free-flight samples that landed inside the segment
  uint64_t clamped = 0;               // collisions whose probabilities were clamped (mu_t > mu_bar)
  uint64_t raised = 0;                // majorants raised where a lookup found mu_t above them

  TrackingCounters& operator+=(const TrackingCounters& o) {
    lookups += o.lookups;
    tentative_collisions += o.tentative_collisions;
    clamped += o.clamped;
    raised += o.raised;
    return *this;
  }
};

}  // namespace nimbus
