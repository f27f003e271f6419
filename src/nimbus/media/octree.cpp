#include "nimbus/media/octree.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>

#include "nimbus/math/rng.h"
#include "nimbus/media/medium_field.h"
#include "nimbus/render/scene.h"

namespace nimbus {
namespace {

// An object whose medium the tree covers.
struct Member {
  const SceneObject* object;
  const Medium* medium;
};

// Bounds of mu_t over a box: the sum over members of sigma_t times their density range there.
struct Bounds3 {
  Rgb hi{0.0}, lo{0.0};
  bool empty = true;
};

// The density range of one member over a box, from the interval of F. Inside a solid, a
// constant medium is constant wherever the ray can be (medium_at ignores F there).
bool density_range(const Member& m, const Box& box, bool solid, double& lo, double& hi) {
  const Box b = intersect(m.object->bounds, box);
  if (b.empty()) return false;  // medium_at only looks at objects whose bounds hold the point
  const Interval F = evaluate(m.object->tape, b);
  if (!(F.hi > 0)) return false;
  const Medium& med = *m.medium;
  switch (med.density) {
    case Medium::Density::Constant:
      lo = solid || F.lo > 0 ? med.scale : 0.0;
      hi = med.scale;
      break;
    case Medium::Density::Field:
      lo = med.scale * std::max(F.lo, 0.0);
      hi = med.scale * F.hi;
      break;
    case Medium::Density::Cloud: {
      const auto [a, b2] = cloud_density_range(F.lo, F.hi, med.cloud.params);
      lo = med.scale * a;
      hi = med.scale * b2;
      break;
    }
  }
  // Where the box reaches past the object's bounds there are points without this medium.
  if (!(b.lo == box.lo && b.hi == box.hi)) lo = 0;
  return true;
}

// Point values sum mu_a and mu_s per medium in another order than these products; a relative
// margin far above round-off keeps the bounds conservative.
constexpr double kRoundOff = 1e-12;

Bounds3 interval_bounds(const std::vector<Member>& members, const Box& box, bool solid) {
  Bounds3 r;
  for (const Member& m : members) {
    double lo = 0, hi = 0;
    // A density bounded by 0 (a cloud eroded away near its surface) is no medium either.
    if (!density_range(m, box, solid, lo, hi) || !(hi > 0)) continue;
    const Rgb sigma_t = m.medium->sigma_a + m.medium->sigma_s;
    r.hi += sigma_t * hi;
    r.lo += sigma_t * lo;
    r.empty = false;
  }
  r.hi *= 1 + kRoundOff;
  r.lo *= 1 - kRoundOff;
  return r;
}

double null_optical_depth(const OctreeNode& n, const Vec3& half) {
  return (n.mu_bar - n.mu_c).max() * 2 * length(half);
}

bool wants_split(const OctreeNode& n, const Vec3& half) {
  if (n.empty) return false;
  bool homogeneous = true;
  for (int c = 0; c < 3; ++c)
    homogeneous = homogeneous && n.mu_bar[c] - n.mu_c[c] <= kOctreeHomogeneous * n.mu_bar[c];
  return !homogeneous && null_optical_depth(n, half) > kOctreeThinNull;
}

Box box_of(const Vec3& center, const Vec3& half) {
  return {center - half, center + half};
}

// The mean chord of the rays crossing a box, 4 V / S (Cauchy).
double mean_chord(const Vec3& half) {
  return 4 * half.x * half.y * half.z / (half.x * half.y + half.y * half.z + half.x * half.z);
}

// The tree as built and the arrays that place its nodes, all in breadth-first order.
struct Grown {
  std::vector<OctreeNode> nodes;
  std::vector<Vec3> centers;
  std::vector<int> levels;
};

// Undoes the splits that do not pay for themselves, bottom up, and compacts the tree. The cost
// of a ray crossing a leaf is one step plus kOctreeLookupCost per expected null collision there,
// (mu_bar − mu_c) times the mean chord; an interior node costs one step plus its children's
// costs, each crossed with probability 1/4 (the ratio of their surfaces). Where the leaf is
// cheaper the children go: a split that only halves the size without tightening the bounds
// costs traversal for nothing.
Grown prune(Grown g, const MajorantOctree& tree) {
  std::vector<double> cost(g.nodes.size());
  for (size_t i = g.nodes.size(); i-- > 0;) {
    OctreeNode& n = g.nodes[i];
    const double leaf = n.empty ? 1.0
                                : 1.0 + kOctreeLookupCost * (n.mu_bar - n.mu_c).max() *
                                            mean_chord(tree.half[g.levels[i]]);
    cost[i] = leaf;
    if (n.children < 0) continue;
    double split = 0;
    for (int k = 0; k < 8; ++k) split += cost[n.children + k];
    split = 1.0 + 0.25 * split;
    if (split < leaf)
      cost[i] = split;
    else
      n.children = -1;
  }
  // Breadth first again, over what is left: children stay contiguous and after their parent.
  Grown out;
  out.nodes.push_back(g.nodes[0]);
  out.centers.push_back(g.centers[0]);
  out.levels.push_back(0);
  std::vector<size_t> from{0};
  for (size_t i = 0; i < out.nodes.size(); ++i) {
    const std::int32_t old_children = g.nodes[from[i]].children;
    if (old_children < 0) continue;
    out.nodes[i].children = static_cast<std::int32_t>(out.nodes.size());
    for (int k = 0; k < 8; ++k) {
      const size_t c = static_cast<size_t>(old_children) + k;
      out.nodes.push_back(g.nodes[c]);
      out.centers.push_back(g.centers[c]);
      out.levels.push_back(g.levels[c]);
      from.push_back(c);
    }
  }
  return out;
}

// The paper's preliminary pass: min and max of mu_t at random points of each non-empty leaf.
// Interior nodes then hold the hull of their children.
void sample_bounds(const Scene& scene, int inside, const std::vector<Vec3>& centers,
                   const std::vector<int>& levels, const MajorantOctree& tree,
                   std::vector<OctreeNode>& nodes) {
  const int samples = std::max(1, scene.settings.tracking.majorant_samples);
  const uint64_t seed = splitmix64(scene.settings.seed ^ 0x6f637472656573ull);
  tbb::parallel_for(size_t{0}, nodes.size(), [&](size_t i) {
    OctreeNode& n = nodes[i];
    if (n.children >= 0 || n.empty) return;
    const Box box = box_of(centers[i], tree.half[levels[i]]);
    Rng rng(seed, i);
    Rgb lo(Box::kInf), hi(0.0);
    for (int s = 0; s < samples; ++s) {
      Vec3 x;
      for (int k = 0; k < 3; ++k) x[k] = box.lo[k] + rng.uniform() * (box.hi[k] - box.lo[k]);
      const Rgb mu = medium_at(scene, x, inside).mu_t();
      for (int c = 0; c < 3; ++c) {
        lo[c] = std::min(lo[c], mu[c]);
        hi[c] = std::max(hi[c], mu[c]);
      }
    }
    n.mu_bar = hi;
    n.mu_c = lo;
  });
  // Children come after their parent, so a backward sweep sees them first.
  for (size_t i = nodes.size(); i-- > 0;) {
    OctreeNode& n = nodes[i];
    if (n.children < 0 || n.empty) continue;
    Rgb lo(Box::kInf), hi(0.0);
    bool any = false;
    for (int k = 0; k < 8; ++k) {
      const OctreeNode& ch = nodes[n.children + k];
      if (ch.empty) continue;
      any = true;
      for (int c = 0; c < 3; ++c) {
        lo[c] = std::min(lo[c], ch.mu_c[c]);
        hi[c] = std::max(hi[c], ch.mu_bar[c]);
      }
    }
    // The parent's interval did not exclude medium, its children's did: nothing to sample.
    n.mu_bar = any ? hi : Rgb(0.0);
    n.mu_c = any ? lo : Rgb(0.0);
  }
}

}  // namespace

MajorantOctree build_majorant_octree(const Scene& scene, int inside) {
  const auto start = std::chrono::steady_clock::now();
  const TrackingSettings& settings = scene.settings.tracking;
  std::vector<Member> members;
  if (inside >= 0) {
    const SceneObject& obj = scene.objects[inside];
    if (obj.medium >= 0) members.push_back({&obj, &scene.media[obj.medium]});
  } else {
    for (int i : scene.field_objects)
      members.push_back({&scene.objects[i], &scene.media[scene.objects[i].medium]});
  }
  MajorantOctree tree;
  for (const Member& m : members) tree.box = unite(tree.box, m.object->bounds);
  if (tree.box.empty()) return tree;
  const bool solid = inside >= 0;
  tree.half[0] = tree.box.extent() * 0.5;
  for (int l = 1; l <= kOctreeMaxDepth; ++l) tree.half[l] = tree.half[l - 1] * 0.5;

  auto make_node = [&](const Vec3& center, const Vec3& half) {
    const Bounds3 b = interval_bounds(members, box_of(center, half), solid);
    OctreeNode n;
    n.mu_bar = b.hi;
    n.mu_c = b.lo;
    n.empty = b.empty;
    return n;
  };
  // Node centers are computed as the walk computes them, so both see the same boxes.
  std::vector<OctreeNode> nodes{make_node(tree.box.center(), tree.half[0])};
  std::vector<Vec3> centers{tree.box.center()};
  std::vector<int> levels{0};
  const int max_depth = std::clamp(settings.octree_depth, 0, kOctreeMaxDepth);
  size_t begin = 0, end = 1;
  for (int level = 0; level < max_depth; ++level) {
    const Vec3& half = tree.half[level];
    struct Candidate {
      double priority;
      size_t node;
    };
    std::vector<Candidate> split;
    for (size_t i = begin; i < end; ++i)
      if (wants_split(nodes[i], half)) split.push_back({null_optical_depth(nodes[i], half), i});
    const size_t room = (kOctreeMaxNodes - nodes.size()) / 8;
    if (split.size() > room) {
      // Keep the nodes where splitting can save the most null collisions; ties by index.
      std::sort(split.begin(), split.end(), [](const Candidate& a, const Candidate& b) {
        return a.priority != b.priority ? a.priority > b.priority : a.node < b.node;
      });
      split.resize(room);
      std::sort(split.begin(), split.end(),
                [](const Candidate& a, const Candidate& b) { return a.node < b.node; });
    }
    if (split.empty()) break;
    const Vec3& child_half = tree.half[level + 1];
    nodes.resize(end + 8 * split.size());
    centers.resize(nodes.size());
    levels.resize(nodes.size(), level + 1);
    tbb::parallel_for(size_t{0}, split.size(), [&](size_t s) {
      const size_t parent = split[s].node, first = end + 8 * s;
      nodes[parent].children = static_cast<std::int32_t>(first);
      for (int k = 0; k < 8; ++k) {
        Vec3 c = centers[parent];
        for (int a = 0; a < 3; ++a) c[a] += (k >> a & 1) ? child_half[a] : -child_half[a];
        centers[first + k] = c;
        nodes[first + k] = make_node(c, child_half);
      }
    });
    begin = end;
    end = nodes.size();
  }
  Grown g = prune({std::move(nodes), std::move(centers), std::move(levels)}, tree);
  tree.depth = *std::max_element(g.levels.begin(), g.levels.end());
  if (settings.majorant_source == TrackingSettings::MajorantSource::Sample)
    sample_bounds(scene, inside, g.centers, g.levels, tree, g.nodes);
  tree.nodes = std::move(g.nodes);
  tree.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return tree;
}

void build_majorant_octrees(Scene& scene) {
  scene.field_octree = build_majorant_octree(scene, -1);
  scene.solid_octrees.assign(scene.objects.size(), MajorantOctree{});
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& obj = scene.objects[i];
    if (obj.medium >= 0 && obj.surface.type != Surface::Type::None)
      scene.solid_octrees[i] = build_majorant_octree(scene, static_cast<int>(i));
  }
}

}  // namespace nimbus
