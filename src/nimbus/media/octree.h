#pragma once
// The majorant octree (docs/design.md, "Majorants and minorants are one structure"): an adaptive
// octree over the media's bounds holding, per node and per channel (bin), a majorant mu_bar and a
// minorant mu_c of mu_t. Free-path estimators get their rates from a front-to-back walk of the
// leaves a ray crosses, so tight bounds where the medium is thin mean few null collisions there.
//
// Bounds (source "bound") come from interval arithmetic: evaluate(tape, node box) for every
// object that may hold medium in the node, mapped through its density model and summed. They
// provably bound mu_t. Source "sample" replaces the leaves' values by the minimum and maximum of
// mu_t at random points (the paper's preliminary pass): tighter, but they may not bound; floored
// by the intervals where the samples missed the medium or saw no variation. Which
// nodes are empty and where the tree splits always come from the intervals, so a sampled tree
// never skips a node that may hold medium.
//
// A node is split, down to the requested depth, unless it is empty, homogeneous
// (mu_bar − mu_c <= kOctreeHomogeneous · mu_bar in every channel), or optically thin for the
// null part (max_c (mu_bar − mu_c) · diagonal <= kOctreeThinNull: a ray crossing it expects at
// most that many null collisions, which no split can improve much). The tree is built level by
// level; when the next level would exceed kOctreeMaxNodes, only the nodes with the largest
// null optical depth (max_c (mu_bar − mu_c) · diagonal) are split, so memory stays bounded at
// any depth and the tree does not depend on the number of threads. Then splits that do not pay
// for themselves are undone, bottom up, by a cost model like a BVH's surface area heuristic:
// a leaf costs a walk step plus kOctreeLookupCost per expected null collision of a ray crossing
// it, an interior node a step plus its children's costs weighted by the chance a ray crossing
// the node crosses them.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "nimbus/frep/tape.h"
#include "nimbus/math/box.h"
#include "nimbus/math/ray.h"
#include "nimbus/media/build_monitor.h"
#include "nimbus/media/medium.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

inline constexpr int kOctreeMaxDepth = 16;
inline constexpr double kOctreeHomogeneous = 0.02;
inline constexpr double kOctreeThinNull = 0.05;
inline constexpr std::size_t kOctreeMaxNodes = std::size_t{1} << 18;
// Sampled bounds (source "sample") keep a residual rate mu_bar − mu_c of at least this fraction
// of the interval bounds' gap, so no heterogeneous leaf passes for homogeneous (octree.cpp).
inline constexpr double kSampledResidualFloor = 0.05;
// The sampling pass (source "sample") looks up at most this many points in all, spreading them
// over the leaves: fewer than majorant_samples per leaf in deep trees.
inline constexpr size_t kOctreeSampleBudget = size_t{1} << 24;
// What a density lookup costs in steps of the walk, for deciding which splits pay off. Measured
// (docs/benchmarks/majorant-octree.md, "The walk"): a procedural cloud lookup about 100 ns against
// about 10 ns per level of a walk's descent plus the tracker's work per segment; at 4 no depth of
// the octree-depth experiment renders slower than a shallower one (at 16, depth 8 was 13 % slower
// than depth 4).
inline constexpr double kOctreeLookupCost = 4;
// A field node listing more media objects than this is split further, past the requested depth
// if need be, and the cost model charges each one past it kOctreeListedCost walk steps (a ray
// crossing the leaf tests its box): the leaves stay short lists however many objects the
// scene holds (issue 26), and scenes of at most this many media objects build as before.
inline constexpr int kOctreeMaxListed = 8;
inline constexpr double kOctreeListedCost = 0.5;
// The most entries the nodes' member lists hold in all while the field's tree over `members`
// objects is built (2^24 at most, 64 MiB): a level whose splits would pass it splits only the
// nodes that gain the most. Never reached with at most kOctreeMaxListed members (every node at
// the budget listing them all); puffs of similar sizes take about 40 per object.
constexpr std::size_t octree_max_list_entries(std::size_t members) {
  const std::size_t few = members < std::size_t(kOctreeMaxListed) ? members : kOctreeMaxListed;
  const std::size_t entries = kOctreeMaxNodes * few + 256 * members;
  return entries < (std::size_t{1} << 24) ? entries : std::size_t{1} << 24;
}

struct OctreeNode {
  // The first of 8 contiguous children, child k in octant (k & 1: upper x, k & 2: upper y,
  // k & 4: upper z); -1 for a leaf.
  std::int32_t children = -1;
  bool empty = true;    // no medium can be in the node
  bool filled = false;  // an object's F > 0 all over the node: a walk in the field needs no
                        // clipping to the objects' insides there (medium_field.h)
};

// Bounds are kept per bin: in rgb mode the three channels; in spectral mode kSpectralBins
// wavelength intervals (spectral/channels.h), each bounding mu_t over its whole interval, so
// any wavelength drawn in it is bounded.
struct MajorantOctree {
  Box box;  // the root's box; empty when there is no medium
  // Half the extent of a node at each level; the build and the walk both place children with it,
  // so they agree on every box to the last bit.
  std::array<Vec3, kOctreeMaxDepth + 1> half{};
  std::vector<OctreeNode> nodes;  // breadth first, nodes[0] the root; empty when no medium
  int bins = 3;
  double majorant_scale = 1;  // OctreeSettings::majorant_scale, applied by the walk
  // Per node, `bins` majorants of mu_t (unscaled), then `bins` minorants.
  std::vector<double> bounds;
  // The field's tree only: per non-empty leaf, the members (indices into the build's list,
  // ascending) whose bounds meet the leaf's box: all that a ray's root finding there need look
  // at (medium_field.h). Node i's are members[member_begin[i], member_begin[i + 1]).
  std::vector<std::uint32_t> member_begin;
  std::vector<std::int32_t> members;
  int depth = 0;  // deepest level reached
  double build_seconds = 0;
  std::size_t built_nodes = 0;  // before pruning: what the build held at its peak
  uint64_t sampled_points = 0;  // points looked up by the sampling pass (source "sample")

  const double* mu_bar(std::size_t node) const { return &bounds[2 * bins * node]; }
  const double* mu_c(std::size_t node) const { return &bounds[2 * bins * node + bins]; }
  std::size_t bytes() const {
    return sizeof(MajorantOctree) + nodes.size() * sizeof(OctreeNode) +
           bounds.size() * sizeof(double) + member_begin.size() * sizeof(std::uint32_t) +
           members.size() * sizeof(std::int32_t);
  }
  bool has_members() const { return !member_begin.empty(); }
  std::span<const std::int32_t> leaf_members(std::int32_t node) const {
    return {members.data() + member_begin[node], members.data() + member_begin[node + 1]};
  }
};

struct OctreeSettings {
  int depth = 4;                // 0: one global node (the baseline)
  bool sampled = false;         // bounds from the paper's sampling pass, else interval bounds
  int samples_per_leaf = 4096;  // points per leaf for the sampling pass (within a total budget)
  double majorant_scale = 1;    // multiplies every majorant at the walk (< 1: not bounding)
  uint64_t seed = 0;            // the sampling pass's random numbers
  bool spectral = false;        // kSpectralBins wavelength bins, else the 3 rgb channels
};

// An object whose medium a tree covers: its function, conservative bounds and medium (an index
// into the media given with it). The tape must outlive the build only.
struct OctreeMember {
  const Tape* tape;
  Box bounds;
  int medium;
};

// The octree over `members`' media: inside one solid object (`solid`: one member, whose medium
// fills it) or over the field of index-matched objects (each medium present where its
// object's F > 0, overlapping media adding up).
MajorantOctree build_majorant_octree(std::span<const Medium> media,
                                     std::span<const OctreeMember> members, bool solid,
                                     const OctreeSettings& settings,
                                     const BuildMonitor& monitor = {});

// Calls leaf(node index, a, b) for every non-empty leaf the ray crosses in [t_min, t_max], front to
// back, with [a, b] the ray's stretch inside it; consecutive stretches share their end points
// exactly. leaf returns false to stop; then so does the walk.
//
// Each stretch starts with a descent from the root to the leaf the ray is in just after t: per
// level one comparison per axis, no stack. A node's mid-plane k is crossed at
// (center[k] − o[k]) / d[k]; the ray is on the plane's upper side just after t when that
// crossing is at or before t (d[k] > 0) or after t (d[k] < 0). The leaf's exit is the nearest
// such crossing after t over the levels descended, so the next descent, at that exit, takes
// the same crossing on its other side: stretches meet exactly and every step makes progress.
// (A descent costs about depth × 3 branch-free steps; the stack walk it replaced spent several
// unpredictable branches per level on children it then mostly did not visit.)
template <class Leaf>
bool walk_octree(const MajorantOctree& tree, const Ray& ray, double t_min, double t_max,
                 Leaf&& leaf) {
  if (tree.nodes.empty()) return true;
  Vec3 inv;
  std::array<bool, 3> down{};  // the ray runs towards lower k (a direction of −0 counts)
  double t = t_min, t_end = t_max;
  for (int k = 0; k < 3; ++k) {
    inv[k] = 1.0 / ray.d[k];
    down[k] = std::signbit(inv[k]);
    // The root box's slab; NaN (a zero direction with the origin on a face) keeps the interval.
    double ta = (tree.box.lo[k] - ray.o[k]) * inv[k], tb = (tree.box.hi[k] - ray.o[k]) * inv[k];
    if (down[k]) std::swap(ta, tb);
    if (ta > t) t = ta;
    if (tb < t_end) t_end = tb;
  }
  const Vec3 root = tree.box.center();
  while (t < t_end) {
    std::int32_t node = 0;
    Vec3 c = root;
    // The leaf's faces, [k][0] lower and [k][1] upper: each the very double that a descent
    // compares against, an ancestor's mid-plane or the root's face.
    double faces[3][2] = {{tree.box.lo.x, tree.box.hi.x},
                          {tree.box.lo.y, tree.box.hi.y},
                          {tree.box.lo.z, tree.box.hi.z}};
    for (int level = 1; tree.nodes[node].children >= 0; ++level) {
      int octant = 0;
      for (int k = 0; k < 3; ++k) {
        // With d[k] = ±0 the crossing is ±inf (or NaN on the plane): the side of o[k] is taken.
        const bool upper = ((c[k] - ray.o[k]) * inv[k] <= t) != down[k];
        octant |= int(upper) << k;
        faces[k][!upper] = c[k];
        const double step[2] = {-tree.half[level][k], tree.half[level][k]};
        c[k] += step[upper];
      }
      node = tree.nodes[node].children + octant;
    }
    // The exit: the nearest crossing of the faces ahead (NaN for a zero direction: skipped).
    double exit = t_end;
    for (int k = 0; k < 3; ++k) exit = std::min(exit, (faces[k][!down[k]] - ray.o[k]) * inv[k]);
    if (!tree.nodes[node].empty && !leaf(node, t, exit)) return false;
    t = exit;
  }
  return true;
}

}  // namespace nimbus
