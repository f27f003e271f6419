#include "nimbus/media/octree.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>

#include "nimbus/math/rng.h"
#include "nimbus/media/medium_field.h"
#include "nimbus/spectral/channels.h"

namespace nimbus {
namespace {

// An object whose medium the tree covers, with its medium's sigma_t bounds per bin.
struct Member {
  const OctreeMember* object;
  const Medium* medium;
  const double* sigma_t_hi;
  const double* sigma_t_lo;
};

// sigma_t = sigma_a + sigma_s of every medium per bin: in rgb mode the channels' values; in
// spectral mode bounds over each bin's wavelength interval (hi, then lo, `bins` each).
std::vector<std::vector<double>> sigma_t_bins(std::span<const Medium> media, bool spectral,
                                              int bins) {
  std::vector<std::vector<double>> out;
  for (const Medium& m : media) {
    std::vector<double> v(2 * bins);
    for (int b = 0; b < bins; ++b) {
      // A textured coefficient lies between its two ends.
      auto bounds = [&](const SpectralParam& from, const SpectralParam& to, const Texture& t) {
        std::pair<double, double> r;
        if (!spectral) {
          r = {from.rgb[b], from.rgb[b]};
          if (t) r = {std::min(r.first, to.rgb[b]), std::max(r.second, to.rgb[b])};
          return r;
        }
        const auto [lo, hi] = spectral_bin_wavelengths(b);  // bins == kSpectralBins here
        r = from.curve->range(lo, hi);
        if (t) {
          const auto [t_lo, t_hi] = to.curve->range(lo, hi);
          r = {std::min(r.first, t_lo), std::max(r.second, t_hi)};
        }
        return r;
      };
      const auto [a_lo, a_hi] = bounds(m.sigma_a, m.sigma_a_to, m.sigma_a_texture);
      const auto [s_lo, s_hi] = bounds(m.sigma_s, m.sigma_s_to, m.sigma_s_texture);
      v[b] = a_hi + s_hi;
      v[bins + b] = std::max(0.0, a_lo + s_lo);
    }
    out.push_back(std::move(v));
  }
  return out;
}

// The density range of one member over a box, from the interval of F. `only_inside`: the walks
// visit only points where F > 0 (inside a solid, the ray stays in the object; in the field, the
// walk is clipped to where some member's F > 0, medium_field.h), so the minorant need hold there
// only; else it must hold over the whole box, where the medium is absent wherever F <= 0 or
// outside the object's bounds.
bool density_range(const Member& m, const Box& box, bool only_inside, double& lo, double& hi) {
  const Box b = intersect(m.object->bounds, box);
  if (b.empty()) return false;  // medium_at only looks at objects whose bounds hold the point
  const Interval F = evaluate(*m.object->tape, b);
  if (!(F.hi > 0)) return false;
  const Medium& med = *m.medium;
  const Interval r = med.density->range(b, F);
  lo = only_inside || (F.lo > 0 && b.lo == box.lo && b.hi == box.hi) ? med.scale * r.lo : 0.0;
  hi = med.scale * r.hi;
  return true;
}

// Point values sum mu_a and mu_s per medium in another order than these products; a relative
// margin far above round-off keeps the bounds conservative.
constexpr double kRoundOff = 1e-12;

// Bounds of mu_t over a box, the sum over the listed members of sigma_t times their density
// range there, into out[0, bins) (majorants) and out[bins, 2 bins) (minorants). False if no
// medium can be in the box. `filled`: some member's F > 0 over the whole box, within its bounds.
bool interval_bounds(const std::vector<Member>& all, std::span<const std::int32_t> listed,
                     const Box& box, bool solid, int bins, double* out, bool& filled) {
  std::fill(out, out + 2 * bins, 0.0);
  // Where one member alone may be present, the clipped walk sees only its inside; where several
  // may, a point inside one of them can be outside another.
  int present = 0;
  filled = false;
  for (const std::int32_t i : listed) {
    const Member& m = all[i];
    const Box b = intersect(m.object->bounds, box);
    if (b.empty()) continue;
    const Interval F = evaluate(*m.object->tape, b);
    present += F.hi > 0;
    filled = filled || (F.lo > 0 && b.lo == box.lo && b.hi == box.hi);
  }
  bool any = false;
  for (const std::int32_t i : listed) {
    const Member& m = all[i];
    double lo = 0, hi = 0;
    // A density bounded by 0 (a cloud eroded away near its surface) is no medium either.
    if (!density_range(m, box, solid || present == 1, lo, hi) || !(hi > 0)) continue;
    for (int b = 0; b < bins; ++b) {
      out[b] += m.sigma_t_hi[b] * hi;
      out[bins + b] += m.sigma_t_lo[b] * lo;
    }
    any = true;
  }
  for (int b = 0; b < bins; ++b) {
    out[b] *= 1 + kRoundOff;
    out[bins + b] *= 1 - kRoundOff;
  }
  return any;
}

// The largest gap between majorant and minorant over the bins.
double null_rate(const double* bounds, int bins) {
  double r = 0;
  for (int b = 0; b < bins; ++b) r = std::max(r, bounds[b] - bounds[bins + b]);
  return r;
}

double null_optical_depth(const double* bounds, int bins, const Vec3& half) {
  return null_rate(bounds, bins) * 2 * length(half);
}

bool wants_split(const OctreeNode& n, const double* bounds, int bins, const Vec3& half) {
  if (n.empty) return false;
  bool homogeneous = true;
  for (int b = 0; b < bins; ++b)
    homogeneous = homogeneous && bounds[b] - bounds[bins + b] <= kOctreeHomogeneous * bounds[b];
  return !homogeneous && null_optical_depth(bounds, bins, half) > kOctreeThinNull;
}

Box box_of(const Vec3& center, const Vec3& half) {
  return {center - half, center + half};
}

// The mean chord of the rays crossing a box, 4 V / S (Cauchy).
double mean_chord(const Vec3& half) {
  return 4 * half.x * half.y * half.z / (half.x * half.y + half.y * half.z + half.x * half.z);
}

// How many members a node lists past kOctreeMaxListed: what the walk's clip tests cost there
// beyond a few objects (0 in any scene of at most that many media objects).
double crowding(const std::vector<std::int32_t>& list) {
  return list.size() > size_t(kOctreeMaxListed) ? double(list.size() - kOctreeMaxListed) : 0.0;
}

// A node's box grown or shrunk by this fraction of its size: its faces, computed from its
// centre, may lie a rounding off its parent's mid-plane or off the bounds that made the root.
constexpr double kNodeMargin = 1e-6;

// The crowding that splitting the node can relieve: of its members, those whose bounds do not
// cover its box (one that covers the box is listed by every child, however deep). The box is
// shrunk by the margin of members_meeting: a node's faces, computed from its centre, may lie a
// rounding outside the bounds that made the root's box.
double relievable_crowding(const std::vector<Member>& all, const std::vector<std::int32_t>& list,
                           const Box& box) {
  if (list.size() <= size_t(kOctreeMaxListed)) return 0;
  const Vec3 margin = box.extent() * kNodeMargin;
  const Vec3 lo = box.lo + margin, hi = box.hi - margin;
  size_t partial = 0;
  for (const std::int32_t i : list) {
    const Box& b = all[i].object->bounds;
    partial += !(b.contains(lo) && b.contains(hi));
  }
  return partial > size_t(kOctreeMaxListed) ? double(partial - kOctreeMaxListed) : 0.0;
}

// The tree as built and the arrays that place its nodes, all in breadth-first order.
struct Grown {
  std::vector<OctreeNode> nodes;
  std::vector<double> bounds;  // 2 bins per node, as MajorantOctree::bounds
  std::vector<Vec3> centers;
  std::vector<int> levels;
  // Per node, the members whose bounds meet its box, ascending: a child looks only at its
  // parent's, so a build does not look at every member in every node.
  std::vector<std::vector<std::int32_t>> lists;
};

// The members of `parent` whose bounds meet the box, grown by a millionth of its size: a
// child's faces are computed from its center, a rounding off the parent's mid-plane, and a
// point's descent (members_at) or a ray's stretch may lie on either side of that plane.
std::vector<std::int32_t> members_meeting(const std::vector<Member>& all,
                                          std::span<const std::int32_t> parent, const Box& box) {
  const Vec3 margin = box.extent() * kNodeMargin;
  const Box grown{box.lo - margin, box.hi + margin};
  std::vector<std::int32_t> out;
  for (const std::int32_t i : parent)
    if (!intersect(all[i].object->bounds, grown).empty()) out.push_back(i);
  return out;
}

// Undoes the splits that do not pay for themselves, bottom up, and compacts the tree. The cost
// of a ray crossing a leaf is one step plus kOctreeLookupCost per expected null collision there,
// (mu_bar − mu_c) times the mean chord; an interior node costs one step plus its children's
// costs, each crossed with probability 1/4 (the ratio of their surfaces). Where the leaf is
// cheaper the children go: a split that only halves the size without tightening the bounds
// costs traversal for nothing.
Grown prune(Grown g, const MajorantOctree& tree) {
  const int bins = tree.bins;
  std::vector<double> cost(g.nodes.size());
  for (size_t i = g.nodes.size(); i-- > 0;) {
    OctreeNode& n = g.nodes[i];
    const double leaf = n.empty ? 1.0
                                : 1.0 +
                                      kOctreeLookupCost * null_rate(&g.bounds[2 * bins * i], bins) *
                                          mean_chord(tree.half[g.levels[i]]) +
                                      kOctreeListedCost * crowding(g.lists[i]);
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
  auto copy_bounds = [&](size_t from_node) {
    const auto first = g.bounds.begin() + 2 * bins * static_cast<std::ptrdiff_t>(from_node);
    out.bounds.insert(out.bounds.end(), first, first + 2 * bins);
  };
  out.nodes.push_back(g.nodes[0]);
  copy_bounds(0);
  out.centers.push_back(g.centers[0]);
  out.levels.push_back(0);
  out.lists.push_back(std::move(g.lists[0]));
  std::vector<size_t> from{0};
  for (size_t i = 0; i < out.nodes.size(); ++i) {
    const std::int32_t old_children = g.nodes[from[i]].children;
    if (old_children < 0) continue;
    out.nodes[i].children = static_cast<std::int32_t>(out.nodes.size());
    for (int k = 0; k < 8; ++k) {
      const size_t c = static_cast<size_t>(old_children) + k;
      out.nodes.push_back(g.nodes[c]);
      copy_bounds(c);
      out.centers.push_back(g.centers[c]);
      out.levels.push_back(g.levels[c]);
      out.lists.push_back(std::move(g.lists[c]));
      from.push_back(c);
    }
  }
  return out;
}

// Floors a bin's sampled majorant mu_bar and minorant mu_c by its interval bounds [lo, hi].
// Samples that all miss the medium (a leaf the medium only touches) give mu_bar = 0, which every
// tracker would take for vacuum: the samples then say nothing and the bounds are kept. Samples
// that all see one value give mu_bar = mu_c, which decomposition and residual ratio tracking
// would take for a homogeneous leaf and never look up: the residual rate mu_bar − mu_c is kept at
// least kSampledResidualFloor of the interval's (hi − lo). Both stay within [lo, hi].
void floor_sampled_bounds(double lo, double hi, double& mu_bar, double& mu_c) {
  if (!(mu_bar > 0)) {
    mu_bar = hi;
    mu_c = lo;
    return;
  }
  const double gap = kSampledResidualFloor * (hi - lo);
  mu_bar = std::min(hi, std::max(mu_bar, mu_c + gap));
  mu_c = std::max(lo, std::min(mu_c, mu_bar - gap));
}

// The paper's preliminary pass: min and max of mu_t at random points of each non-empty leaf,
// per bin (in spectral mode from each medium's sigma_t bounds over the bin). Interior nodes then
// hold the hull of their children.
// The members as the media layer's point lookup wants them (media_scene.h).
struct MemberObject {
  const Tape& tape;
  const Box& bounds;
  int medium;
};
struct MemberScene {
  std::span<const Medium> media;
  std::span<const MemberObject> objects;
  std::span<const std::int32_t> field_objects;  // a leaf's members, for the field
};

// Progress: the interval phase reports levels done as the first half, the sampling pass leaves
// done as the second.
void sample_bounds(std::span<const Medium> media, std::span<const MemberObject> objects, bool solid,
                   const OctreeSettings& settings, const std::vector<std::vector<double>>& sigma_t,
                   MajorantOctree& tree, Grown& g, BuildWatch& watch) {
  // At most kOctreeSampleBudget points in all: a deep tree gets fewer per leaf (at depth 16 with
  // 4 096 per leaf the pass had not finished after 60 s).
  size_t leaves = 0;
  for (const OctreeNode& n : g.nodes) leaves += n.children < 0 && !n.empty;
  const size_t affordable = std::max<size_t>(1, kOctreeSampleBudget / std::max<size_t>(leaves, 1));
  const int samples = static_cast<int>(
      std::min<size_t>(affordable, size_t(std::max(1, settings.samples_per_leaf))));
  tree.sampled_points = uint64_t(samples) * leaves;
  const int bins = tree.bins;
  const uint64_t seed = splitmix64(settings.seed ^ 0x6f637472656573ull);
  std::atomic<size_t> leaves_done{0};
  tbb::parallel_for(size_t{0}, g.nodes.size(), [&](size_t i) {
    const OctreeNode& n = g.nodes[i];
    if (n.children >= 0 || n.empty || watch.cancelled()) return;
    watch.report(0.5 + 0.5 * double(leaves_done.fetch_add(1)) / double(leaves));
    const Box box = box_of(g.centers[i], tree.half[g.levels[i]]);
    Rng rng(seed, i);
    const MemberScene scene{media, objects, g.lists[i]};
    const int inside = solid ? 0 : -1;
    double* out = &g.bounds[2 * bins * i];
    const std::vector<double> interval(out, out + 2 * bins);
    std::fill(out, out + bins, 0.0);
    std::fill(out + bins, out + 2 * bins, Box::kInf);
    std::vector<double> mu(2 * bins);
    for (int s = 0; s < samples; ++s) {
      Vec3 x;
      for (int k = 0; k < 3; ++k) x[k] = box.lo[k] + rng.uniform() * (box.hi[k] - box.lo[k]);
      std::fill(mu.begin(), mu.end(), 0.0);
      for_each_medium_at(scene, x, inside, [&](int medium, double density, double, int) {
        for (int b = 0; b < 2 * bins; ++b) mu[b] += density * sigma_t[medium][b];
      });
      for (int b = 0; b < bins; ++b) {
        out[b] = std::max(out[b], mu[b]);
        out[bins + b] = std::min(out[bins + b], mu[bins + b]);
      }
    }
    for (int b = 0; b < bins; ++b)
      floor_sampled_bounds(interval[bins + b], interval[b], out[b], out[bins + b]);
  });
  // Children come after their parent, so a backward sweep sees them first.
  for (size_t i = g.nodes.size(); i-- > 0;) {
    const OctreeNode& n = g.nodes[i];
    if (n.children < 0 || n.empty) continue;
    double* out = &g.bounds[2 * bins * i];
    std::fill(out, out + bins, 0.0);
    std::fill(out + bins, out + 2 * bins, Box::kInf);
    bool any = false;
    for (int k = 0; k < 8; ++k) {
      const size_t c = static_cast<size_t>(n.children) + k;
      if (g.nodes[c].empty) continue;
      any = true;
      const double* ch = &g.bounds[2 * bins * c];
      for (int b = 0; b < bins; ++b) {
        out[b] = std::max(out[b], ch[b]);
        out[bins + b] = std::min(out[bins + b], ch[bins + b]);
      }
    }
    // The parent's interval did not exclude medium, its children's did: nothing to sample.
    if (!any) std::fill(out, out + 2 * bins, 0.0);
  }
}

}  // namespace

MajorantOctree build_majorant_octree(std::span<const Medium> media,
                                     std::span<const OctreeMember> holders, bool solid,
                                     const OctreeSettings& settings, const BuildMonitor& monitor) {
  const auto start = std::chrono::steady_clock::now();
  BuildWatch watch(monitor);
  MajorantOctree tree;
  tree.bins = settings.spectral ? kSpectralBins : 3;
  tree.majorant_scale = settings.majorant_scale;
  const int bins = tree.bins;
  const std::vector<std::vector<double>> sigma_t = sigma_t_bins(media, settings.spectral, bins);
  std::vector<Member> members;
  for (const OctreeMember& h : holders) {
    const std::vector<double>& s = sigma_t[h.medium];
    members.push_back(Member{&h, &media[h.medium], s.data(), s.data() + bins});
  }
  for (const Member& m : members) tree.box = unite(tree.box, m.object->bounds);
  if (tree.box.empty()) {
    watch.report(1);
    return tree;
  }
  tree.half[0] = tree.box.extent() * 0.5;
  for (int l = 1; l <= kOctreeMaxDepth; ++l) tree.half[l] = tree.half[l - 1] * 0.5;

  auto make_node = [&](const Vec3& center, const Vec3& half, double* bounds,
                       std::span<const std::int32_t> parent_list, std::vector<std::int32_t>& list) {
    const Box box = box_of(center, half);
    list = members_meeting(members, parent_list, box);
    OctreeNode n;
    n.empty = !interval_bounds(members, list, box, solid, bins, bounds, n.filled);
    return n;
  };
  // Node centers are computed as the walk computes them, so both see the same boxes.
  Grown g;
  g.bounds.resize(2 * bins);
  std::vector<std::int32_t> everyone(members.size());
  for (size_t i = 0; i < members.size(); ++i) everyone[i] = static_cast<std::int32_t>(i);
  g.lists.emplace_back();
  g.nodes.push_back(
      make_node(tree.box.center(), tree.half[0], g.bounds.data(), everyone, g.lists[0]));
  g.centers.push_back(tree.box.center());
  g.levels.push_back(0);
  const int max_depth = std::clamp(settings.depth, 0, kOctreeMaxDepth);
  size_t begin = 0, end = 1;
  size_t list_entries = g.lists[0].size();
  const size_t max_entries = octree_max_list_entries(members.size());
  const double interval_share = settings.sampled ? 0.5 : 1.0;
  // Levels past the requested depth split only nodes that list too many objects.
  for (int level = 0; level < kOctreeMaxDepth; ++level) {
    if (watch.cancelled()) return tree;
    watch.report(interval_share * std::min(1.0, double(level) / std::max(max_depth, 1)));
    const Vec3& half = tree.half[level];
    struct Candidate {
      double priority;
      size_t node;
    };
    std::vector<Candidate> split;
    size_t new_entries = 0;  // at most, in the children's lists
    for (size_t i = begin; i < end; ++i) {
      const double* b = &g.bounds[2 * bins * i];
      const double crowded =
          g.nodes[i].empty ? 0.0
                           : relievable_crowding(members, g.lists[i], box_of(g.centers[i], half));
      if ((level < max_depth && wants_split(g.nodes[i], b, bins, half)) || crowded > 0) {
        split.push_back({null_optical_depth(b, bins, half) + crowded, i});
        new_entries += 8 * g.lists[i].size();
      }
    }
    const size_t room = (kOctreeMaxNodes - g.nodes.size()) / 8;
    if (split.size() > room || list_entries + new_entries > max_entries) {
      // Keep the nodes where splitting can save the most null collisions, within the budgets of
      // nodes and list entries; ties by index.
      std::sort(split.begin(), split.end(), [](const Candidate& a, const Candidate& b) {
        return a.priority != b.priority ? a.priority > b.priority : a.node < b.node;
      });
      size_t kept = 0;
      for (size_t entries = list_entries; kept < std::min(room, split.size()); ++kept) {
        entries += 8 * g.lists[split[kept].node].size();
        if (entries > max_entries) break;
      }
      split.resize(kept);
      std::sort(split.begin(), split.end(),
                [](const Candidate& a, const Candidate& b) { return a.node < b.node; });
    }
    if (split.empty()) break;
    const Vec3& child_half = tree.half[level + 1];
    g.nodes.resize(end + 8 * split.size());
    g.bounds.resize(2 * bins * g.nodes.size());
    g.centers.resize(g.nodes.size());
    g.levels.resize(g.nodes.size(), level + 1);
    g.lists.resize(g.nodes.size());
    tbb::parallel_for(size_t{0}, split.size(), [&](size_t s) {
      const size_t parent = split[s].node, first = end + 8 * s;
      g.nodes[parent].children = static_cast<std::int32_t>(first);
      for (int k = 0; k < 8; ++k) {
        Vec3 c = g.centers[parent];
        for (int a = 0; a < 3; ++a) c[a] += (k >> a & 1) ? child_half[a] : -child_half[a];
        g.centers[first + k] = c;
        g.nodes[first + k] = make_node(c, child_half, &g.bounds[2 * bins * (first + k)],
                                       g.lists[parent], g.lists[first + k]);
      }
    });
    for (size_t i = end; i < g.nodes.size(); ++i) list_entries += g.lists[i].size();
    begin = end;
    end = g.nodes.size();
  }
  tree.built_nodes = g.nodes.size();
  g = prune(std::move(g), tree);
  tree.depth = *std::max_element(g.levels.begin(), g.levels.end());
  if (settings.sampled) {
    std::vector<MemberObject> objects;
    for (const OctreeMember& h : holders) objects.push_back({*h.tape, h.bounds, h.medium});
    sample_bounds(media, objects, solid, settings, sigma_t, tree, g, watch);
    if (watch.cancelled()) return tree;
  }
  if (!solid) {
    tree.member_begin.reserve(g.nodes.size() + 1);
    for (size_t i = 0; i < g.nodes.size(); ++i) {
      tree.member_begin.push_back(static_cast<std::uint32_t>(tree.members.size()));
      if (g.nodes[i].children < 0 && !g.nodes[i].empty)
        tree.members.insert(tree.members.end(), g.lists[i].begin(), g.lists[i].end());
    }
    tree.member_begin.push_back(static_cast<std::uint32_t>(tree.members.size()));
  }
  tree.nodes = std::move(g.nodes);
  tree.bounds = std::move(g.bounds);
  tree.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  watch.report(1);
  return tree;
}

}  // namespace nimbus
