#pragma once
// The paper's Table 2 / Fig. 7: octree depth against build time, memory and tracking cost.
// Renders scenes/bench/cloud_octree.json (a dense heterogeneous cloud beside a free-form object
// holding a haze) with delta tracking at each octree depth with the same samples and seed, so
// that every depth renders the same expected image and only the tracking work differs. Each depth
// is built and rendered 3 times and the shortest times are kept: on a shared machine the least
// disturbed run is the best estimate (the counters are identical). Full: depths 0, 1, 2, 4, 8,
// 12, 16 at the scene's 160×96 and 4 spp; quick: depths 0, 2, 4 at 32×20, 1 spp, once.
//
// Writes octree_depth.csv, one row per depth: build seconds, nodes, bytes, the deepest level
// reached, render seconds, density lookups and majorant segments per pixel sample, the null
// fraction (null / tentative collisions), lookups per real collision, and render time and lookups
// relative to depth 1 (as the paper's Table 2; 0 when depth 1 was not run).

#include "nimbus/experiments/experiment.h"

namespace nimbus {

ExperimentReport run_octree_depth(const ExperimentOptions& options);

}  // namespace nimbus
