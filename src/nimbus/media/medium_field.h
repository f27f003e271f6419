#pragma once
// The medium as a field (docs/design.md, "The medium is a field"): wherever an index-matched
// object's function is positive its medium is present, and overlapping media add. Inside a solid
// object (a dielectric with a medium) only that object's medium is present: a solid displaces the
// media around it.
// Everything here works on a path's N channels (spectral/channels.h) and on any scene that has
// what the media layer needs (media_scene.h).

#include <algorithm>
#include <array>
#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

#include "nimbus/frep/intersect.h"
#include "nimbus/math/box.h"
#include "nimbus/math/mat4.h"
#include "nimbus/math/ray.h"
#include "nimbus/media/media_scene.h"
#include "nimbus/media/medium.h"
#include "nimbus/media/member_grid.h"
#include "nimbus/media/octree.h"
#include "nimbus/media/phase.h"
#include "nimbus/spectral/channels.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

// Any number of media may overlap at a point; media of one anisotropy g share one lobe of the
// mixture phase function (the mixture is Σ_i mu_s,i HG(g_i) / mu_s, so their mu_s,i add). The
// index-matched media of a scene may have at most this many different g (compile.h checks);
// inside a solid only its own medium is present.
inline constexpr int kMaxPhaseLobes = 16;

// A member grid's cell lists this long or shorter are box-tested with branches, longer ones
// without (for_each_medium_at).
inline constexpr std::size_t kShortMemberList = 4;

// The coefficients at a point, with the phase function of the mixture of media present there.
template <int N>
struct MediumPoint {
  Spectrum<N> mu_a{0.0}, mu_s{0.0};
  Spectrum<N> mu_a_Le{0.0};  // Σ mu_a,i L_e,i
  int lobes = 0;             // how many different g the media present have
  std::array<double, kMaxPhaseLobes> g{};
  std::array<Spectrum<N>, kMaxPhaseLobes> mu_s_i{};  // each lobe's scattering coefficient
  Spectrum<N> mu_t() const { return mu_a + mu_s; }
};

// The density (the factor on sigma_a, sigma_s) of `medium` at x, where its object's F is F.
double medium_density(const Medium& medium, const Vec3& x, double F);

// Calls f(medium index, density, F, object index) for each medium present at x, seen from
// `inside`, the solid object the point is in (-1: none), in the order of the scene's field
// objects. In the field,
// a scene with a member grid (member_grid.h) looks only at the objects listed for x's cell.
template <MediumHolders S, class F>
void for_each_medium_at(const S& scene, const Vec3& x, int inside, F&& f) {
  if (inside >= 0) {
    const auto& obj = scene.objects[inside];
    if (obj.medium < 0) return;
    const Medium& medium = scene.media[obj.medium];
    const double F_x = medium_uses_F(medium) ? evaluate(obj.tape, x) : 1.0;
    const double d = medium_density(medium, x, F_x);
    if (d > 0) f(obj.medium, d, F_x, inside);
    return;
  }
  // The medium of object i, whose bounds hold x and whose F there is F_x.
  auto add = [&](int medium, double F_x, int i) {
    if (F_x <= 0) return;
    const double d = medium_density(scene.media[medium], x, F_x);
    if (d > 0) f(medium, d, F_x, i);
  };
  auto visit = [&](int i) { add(scene.objects[i].medium, evaluate(scene.objects[i].tape, x), i); };
  if constexpr (requires { scene.field_grid; }) {
    const MemberGrid& grid = scene.field_grid;
    if (!grid.begin.empty()) {
      const std::span<const std::int32_t> listed = members_at(grid, x);
      // Object k, whose bounds hold x (inlined at both calls: as a call it cost four puffs 9 %).
      auto take = [&](std::int32_t k) __attribute__((always_inline)) {
        if (grid.single[k])
          add(grid.medium[k], grid.objects[k].quadric.eval(x),  // as evaluate(tape, x), to the bit
              scene.field_objects[k]);
        else
          visit(scene.field_objects[k]);
      };
      // A short list is tested with branches: along a ray their outcomes repeat, and the branch
      // predictor learns them (docs/benchmarks/scenes-at-scale.md, "Box tests without branches").
      if (listed.size() <= kShortMemberList) {
        for (const std::int32_t k : listed)
          if (grid.objects[k].bounds.contains(x)) take(k);
        return;
      }
      // A longer list's box tests run first, without branches, into a list of those passed:
      // which of many objects hold x is unpredictable, and many of their branches would be
      // mispredicted.
      constexpr std::size_t kBatch = 32;
      std::array<std::int32_t, kBatch> held;
      for (std::size_t base = 0; base < listed.size(); base += kBatch) {
        const std::size_t n = std::min(kBatch, listed.size() - base);
        std::size_t count = 0;
        for (std::size_t j = 0; j < n; ++j) {
          const std::int32_t k = listed[base + j];
          const Box& b = grid.objects[k].bounds;
          held[count] = k;
          count += (x.x >= b.lo.x) & (x.x <= b.hi.x) & (x.y >= b.lo.y) & (x.y <= b.hi.y) &
                   (x.z >= b.lo.z) & (x.z <= b.hi.z);
        }
        for (std::size_t j = 0; j < count; ++j) take(held[j]);
      }
      return;
    }
  }
  for (int i : scene.field_objects)
    if (scene.objects[i].bounds.contains(x)) visit(i);
}

// Where the textures of object i are evaluated for the scene point x: in its own coordinates
// where the scene places textured objects by frames (render/scene.h, texture_point), else x.
template <MediumHolders S>
Vec3 texture_point_of(const S& scene, int i, const Vec3& x) {
  if constexpr (requires { scene.texture_frames; }) {
    const int frame = scene.objects[size_t(i)].texture_frame;
    return frame < 0 ? x : transform_point(scene.texture_frames[size_t(frame)], x);
  } else {
    return x;
  }
}

namespace medium_field_detail {

// Adds a medium of coefficients c at density `density` at x, where its object's F is F, to the
// sums mu_a, mu_s and mu_a_Le = Σ mu_a,i L_e,i; returns the medium's own mu_s. Its textures are
// evaluated at x_texture, x in the object's coordinates.
template <int N>
Spectrum<N> add_medium(const MediumCoefficients<N>& c, double density, const Vec3& x,
                       const Vec3& x_texture, double F, Spectrum<N>& mu_a, Spectrum<N>& mu_s,
                       Spectrum<N>& mu_a_Le) {
  Spectrum<N> a = c.sigma_a, s = c.sigma_s;
  if (c.sigma_a_texture) [[unlikely]]
    a += (c.sigma_a_to - c.sigma_a) * c.sigma_a_texture->at(x_texture, F);
  if (c.sigma_s_texture) [[unlikely]]
    s += (c.sigma_s_to - c.sigma_s) * c.sigma_s_texture->at(x_texture, F);
  a *= density;
  s *= density;
  mu_a += a;
  mu_s += s;
  if (c.emission_grid)
    mu_a_Le += a * temperature_emission_at<N>(*c.emission_grid, x, c.spectral, c.lambda);
  else
    mu_a_Le += a * c.emission;
  return s;
}

}  // namespace medium_field_detail

// The coefficients at x seen from `inside`, with each medium's coefficients at the path's
// channels in `coefficients` (indexed as scene.media), written into m. Only the first m.lobes
// entries of m's per-medium arrays are set: filling a point in place, rather than returning a
// fresh one, spares a tracker that looks up many points the copy and clearing of those arrays.
template <int N, MediumHolders S>
void medium_at(const S& scene, const std::vector<MediumCoefficients<N>>& coefficients,
               const Vec3& x, int inside, MediumPoint<N>& m) {
  m.mu_a = m.mu_s = m.mu_a_Le = Spectrum<N>(0.0);
  m.lobes = 0;
  for_each_medium_at(scene, x, inside, [&](int medium, double density, double F, int object) {
    const MediumCoefficients<N>& c = coefficients[medium];
    const Vec3 x_texture =
        c.sigma_a_texture || c.sigma_s_texture ? texture_point_of(scene, object, x) : x;
    const Spectrum<N> mu_s_i =
        medium_field_detail::add_medium(c, density, x, x_texture, F, m.mu_a, m.mu_s, m.mu_a_Le);
    const double g = scene.media[medium].g;
    int lobe = 0;
    while (lobe < m.lobes && m.g[lobe] != g) ++lobe;
    if (lobe == m.lobes) {
      if (lobe == kMaxPhaseLobes)
        throw std::logic_error(
            "more different phase anisotropies at a point than "
            "kMaxPhaseLobes: the scene was not checked (compile.h)");
      m.g[lobe] = g;
      m.mu_s_i[lobe] = Spectrum<N>(0.0);
      ++m.lobes;
    }
    m.mu_s_i[lobe] += mu_s_i;
  });
}

template <int N, MediumHolders S>
MediumPoint<N> medium_at(const S& scene, const std::vector<MediumCoefficients<N>>& coefficients,
                         const Vec3& x, int inside) {
  MediumPoint<N> m;
  medium_at(scene, coefficients, x, inside, m);
  return m;
}

// The sums mu_a, mu_s and mu_a_Le at x seen from `inside`, without the phase functions: all that
// a transmittance estimate needs.
template <int N, MediumHolders S>
void medium_sums_at(const S& scene, const std::vector<MediumCoefficients<N>>& coefficients,
                    const Vec3& x, int inside, Spectrum<N>& mu_a, Spectrum<N>& mu_s,
                    Spectrum<N>& mu_a_Le) {
  mu_a = mu_s = mu_a_Le = Spectrum<N>(0.0);
  for_each_medium_at(scene, x, inside, [&](int medium, double density, double F, int object) {
    const MediumCoefficients<N>& c = coefficients[medium];
    const Vec3 x_texture =
        c.sigma_a_texture || c.sigma_s_texture ? texture_point_of(scene, object, x) : x;
    medium_field_detail::add_medium(c, density, x, x_texture, F, mu_a, mu_s, mu_a_Le);
  });
}

// A stretch of a ray with a majorant mu_bar and a minorant mu_c of mu_t there, per channel.
// mu_bar is multiplied by the octree's majorant scale, so it need not bound when that is < 1.
template <int N>
struct MajorantSegment {
  double t0, t1;
  Spectrum<N> mu_bar;
  Spectrum<N> mu_c{0.0};
};

// A stretch [t0, t1] of a ray. Without initialisers, so that the spans of a walk are not
// zero-filled each time (only the first `count` are ever read).
struct Span {
  double t0, t1;
};

// Where the field's media can be along a ray: the stretches of [t_min, t_max] where some
// index-matched medium object's F > 0, found from the exact roots of F along the ray (its
// surface, frep/intersect.h), sorted and disjoint. Surfaces are exact, so an octree leaf that
// straddles an object's boundary costs nothing outside it.
struct MediumIntervals {
  static constexpr int kMax = 32;
  int count = 0;
  std::array<Span, kMax> spans;
};

// How far past a root, relative to the object's size, the search for the next one starts
// (add_object_spans).
inline constexpr double kRootSkip = 1e-9;

// Adds [a, b] to sorted disjoint spans, merging those it overlaps or touches. False, leaving m
// as it was, when there is no room left.
bool add_span(MediumIntervals& m, double a, double b);

// The object's stretches with F > 0 over [t0, t1] (within its bounds), added to m. False when m
// ran out of room.
bool add_object_spans(const Tape& tape, const Box& bounds, const Ray& ray, double t0, double t1,
                      MediumIntervals& m);

// The field objects whose stretches a walk has added: the few that the leaves crossed so far
// list. When it is full it starts again; adding an object's stretches twice changes nothing.
struct SpannedObjects {
  static constexpr int kMax = 64;
  int count = 0;
  bool restarted = false;
  std::array<std::int32_t, kMax> ids;
  bool contains(std::int32_t id) const {
    for (int i = 0; i < count; ++i)
      if (ids[i] == id) return true;
    return false;
  }
};

// Drops the spans that end at or before t: a walk past t never looks at them again.
void drop_spans_before(MediumIntervals& m, double t);

// Adds to `spans` the stretches of [t0, t1] past `a` where the listed field objects (indices
// into scene.field_objects) that the ray meets in the leaf's stretch [a, b] and that are not
// yet in `spanned` have F > 0. Each object's roots are searched over the whole [t0, t1],
// whichever leaf first lists it, so they do not depend on the leaves. False when they do not fit
// (then the walk takes the leaf's whole stretch with a minorant of 0, which holds everywhere);
// `changed` says whether spans changed.
template <MediumHolders S>
bool add_leaf_spans(const S& scene, std::span<const std::int32_t> listed, const Ray& ray, double t0,
                    double t1, double a, double b, MediumIntervals& spans, SpannedObjects& spanned,
                    bool& changed) {
  for (const std::int32_t k : listed) {
    const auto& obj = scene.objects[scene.field_objects[k]];
    double from = a, to = b;  // objects the ray does not meet in this leaf can wait
    if (!clip_ray(obj.bounds, ray, from, to) || spanned.contains(k)) continue;
    MediumIntervals own;
    if (!add_object_spans(obj.tape, obj.bounds, ray, t0, t1, own)) return false;
    for (int i = 0; i < own.count; ++i) {
      if (own.spans[i].t1 <= a) continue;
      if (!add_span(spans, own.spans[i].t0, own.spans[i].t1)) {
        drop_spans_before(spans, a);
        if (!add_span(spans, own.spans[i].t0, own.spans[i].t1)) return false;
      }
      changed = true;
    }
    if (spanned.count == SpannedObjects::kMax) {
      spanned.count = 0;
      spanned.restarted = true;
    }
    spanned.ids[spanned.count++] = k;
  }
  return true;
}

// Calls f(const MajorantSegment<N>&) for the majorant segments covering the media along the ray
// in [t_min, t_max], in order, from the leaves of the scene's majorant octree (octree.h) for
// `inside` (-1: the field; else that solid object), each channel taking its bin's bounds. Where
// no medium can be there is a gap: in the field, the leaves' stretches are clipped to where an
// object's F > 0 (add_leaf_spans, from the objects each leaf lists), which the octree's
// minorants rely on, except in leaves that an object fills (no surface crosses them), so a walk
// that stays in such leaves finds no roots; inside a solid the ray never leaves the object.
// Neighbouring leaves with identical bounds become one segment.
// f returns false to stop the walk. The ray direction must be unit length.
template <int N, MediaScene S, class F>
void walk_majorant_segments(const S& scene, const Channels<N>& ch, const Ray& ray, double t_min,
                            double t_max, int inside, F&& f) {
  if (inside >= 0 && scene.objects[inside].medium < 0) return;  // a solid without a medium
  // at(): a scene whose octrees were never built fails loudly rather than reading past the end.
  const MajorantOctree& tree = inside >= 0 ? scene.solid_octrees.at(inside) : scene.field_octree;
  if (tree.nodes.empty()) return;
  // In the field, an object's spans are found (by root finding) only once the walk meets a
  // leaf that lists it and that an object's surface may cross: a walk within filled leaves
  // needs none.
  MediumIntervals spans;
  SpannedObjects spanned;
  double t0 = t_min, t1 = t_max;
  if (inside >= 0) {
    spans.count = 1;
    spans.spans[0] = {t_min, t_max};
  } else if (!clip_ray(tree.box, ray, t0, t1) || !(t1 > t0)) {
    return;
  }
  // The tree's majorant scale times each channel's factor from its bin to its own wavelength
  // (exactly the scale in rgb mode, where the factors are 1).
  std::array<double, N> scale;
  for (int c = 0; c < N; ++c) scale[c] = tree.majorant_scale * ch.majorant_factor[c];
  MajorantSegment<N> pending{0, 0, Spectrum<N>(0.0), Spectrum<N>(0.0)};
  bool has_pending = false;
  int span = 0;          // the first span that may overlap the current leaf
  bool stopped = false;  // f asked to stop
  auto emit = [&](double a, double b, const Spectrum<N>& mu_bar, const Spectrum<N>& mu_c) {
    if (has_pending && a == pending.t1 && mu_bar == pending.mu_bar && mu_c == pending.mu_c) {
      pending.t1 = b;
      return true;
    }
    if (has_pending && !f(std::as_const(pending))) return !(stopped = true);
    pending = {a, b, mu_bar, mu_c};
    has_pending = true;
    return true;
  };
  walk_octree(tree, ray, t0, t1, [&](std::int32_t node, double a, double b) {
    const double* hi = tree.mu_bar(node);
    const double* lo = tree.mu_c(node);
    Spectrum<N> mu_bar, mu_c;
    for (int c = 0; c < N; ++c) {
      mu_bar[c] = hi[ch.bin[c]] * scale[c];
      mu_c[c] = lo[ch.bin[c]];
    }
    if (tree.nodes[node].filled) return emit(a, b, mu_bar, mu_c);
    if (inside < 0) {
      bool changed = false;
      if (!tree.has_members() || !add_leaf_spans(scene, tree.leaf_members(node), ray, t0, t1, a, b,
                                                 spans, spanned, changed))
        return emit(a, b, mu_bar, Spectrum<N>(0.0));
      if (changed) span = 0;
    }
    while (span < spans.count && spans.spans[span].t1 <= a) ++span;
    // Past the last span: done, unless leaves ahead may list objects not searched yet.
    if (span == spans.count)
      return inside < 0 &&
             (spanned.restarted || size_t(spanned.count) < scene.field_objects.size());
    if (spans.spans[span].t0 >= b) return true;
    for (int k = span; k < spans.count && spans.spans[k].t0 < b; ++k)
      if (!emit(std::max(a, spans.spans[k].t0), std::min(b, spans.spans[k].t1), mu_bar, mu_c))
        return false;
    return true;
  });
  // The walk also stops once past the last span; a pending segment is then still due.
  if (!stopped && has_pending) f(std::as_const(pending));
}

// The mixture phase function at a scattering point: value per channel.
template <int N>
Spectrum<N> phase_value(const MediumPoint<N>& m, double cos_theta) {
  Spectrum<N> p(0.0);
  for (int i = 0; i < m.lobes; ++i) p += m.mu_s_i[i] * hg_phase(cos_theta, m.g[i]);
  for (int c = 0; c < N; ++c) p[c] = m.mu_s[c] > 0 ? p[c] / m.mu_s[c] : 0.0;
  return p;
}

// The density with which sample_phase picks a direction.
template <int N>
double phase_pdf(const MediumPoint<N>& m, double cos_theta) {
  const double total = m.mu_s.sum();
  if (m.lobes == 1 || total <= 0) return hg_phase(cos_theta, m.g[0]);
  double pdf = 0;
  for (int i = 0; i < m.lobes; ++i) pdf += m.mu_s_i[i].sum() / total * hg_phase(cos_theta, m.g[i]);
  return pdf;
}

// Picks a medium with probability ∝ its average mu_s, then samples its HG lobe; returns the
// direction and the per-channel weight phase_value / pdf (exactly 1 for a single medium).
template <int N>
Vec3 sample_phase(const MediumPoint<N>& m, const Vec3& dir, double u0, double u1, double u2,
                  Spectrum<N>& weight, double& pdf) {
  if (m.lobes <= 1) {
    const Vec3 w = sample_hg(dir, m.g[0], u1, u2);
    weight = Spectrum<N>(1.0);
    pdf = hg_phase(dot(dir, w), m.g[0]);
    return w;
  }
  // One-sample mixture: pick a lobe ∝ its share of mu_s, weight by the exact mixture.
  const double total = m.mu_s.sum();
  int pick = m.lobes - 1;
  double acc = 0;
  for (int i = 0; i < m.lobes; ++i) {
    acc += m.mu_s_i[i].sum() / total;
    if (u0 < acc) {
      pick = i;
      break;
    }
  }
  const Vec3 w = sample_hg(dir, m.g[pick], u1, u2);
  const double cos_theta = dot(dir, w);
  pdf = phase_pdf(m, cos_theta);
  weight = pdf > 0 ? phase_value(m, cos_theta) / pdf : Spectrum<N>(0.0);
  return w;
}

}  // namespace nimbus
