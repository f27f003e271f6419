#pragma once
// Manifold next-event estimation (Hanika, Droske & Fascione 2015) through smooth dielectric
// boundaries: the specular chain that joins a scattering vertex to a light through one solid's
// boundary (one refraction from inside it, two through it from outside), found by Newton's
// method on the chain's first direction, and the generalized geometry term that turns the
// light's measure into the vertex's solid angle. docs/media.md, "Light through smooth
// boundaries", states what it assumes.
//
// The walk is deterministic: the same start and target give the same chain. The path loop uses
// that to weigh it against BSDF and phase sampling by MIS (render/manifold_light.h): a sampled
// path that reaches a light through such a chain has the walk's density where the walk finds it.

#include <optional>

#include "nimbus/math/vec3.h"
#include "nimbus/render/counters.h"
#include "nimbus/render/scene.h"

namespace nimbus {

// The vertex a chain leaves from: a medium point, or a diffuse surface point with the normal on
// the side the path is on. `inside`: the solid the vertex is in, or -1. `boundary`: for a point
// on a rough dielectric boundary, which scatters to both sides, that solid (n is then its outward
// normal); -1 elsewhere. Manifold sampling does not start from such points.
struct ChainStart {
  Vec3 p;
  Vec3 n;
  bool on_surface = false;
  int inside = -1;
  int boundary = -1;
};

// The solid a ray leaving `at` in direction w is in: across a rough dielectric boundary, the solid
// on w's side of it (one level: the space around a solid is outside every solid).
inline int side_of(const ChainStart& at, const Vec3& w) {
  if (at.boundary < 0) return at.inside;
  return dot(w, at.n) < 0 ? at.boundary : (at.inside == at.boundary ? -1 : at.inside);
}

// A point on a light (point lights, sphere lights), or a direction towards one at infinity.
struct ChainTarget {
  Vec3 point;      // when !at_infinity
  Vec3 direction;  // when at_infinity: unit, towards the light
  bool at_infinity = false;
};

struct SpecularChain {
  int solid = -1;           // the object whose boundary refracts
  int vertices = 0;         // 1 (the start is inside the solid) or 2 (in, then out)
  Vec3 x[2];                // the refraction points, in path order from the start
  Vec3 n[2];                // the outward normals there
  Vec3 dir0;                // the direction leaving the start (unit)
  Vec3 dir_out;             // the direction leaving the last refraction, towards the light (unit)
  double transmission = 1;  // ∏ (1 − F): the probability that sampling takes every refraction
  // The generalized geometry term: |dω₀ / dA⊥| for a target point (A⊥: area across dir_out at
  // the target), |dω₀ / dω_out| for a target at infinity.
  double jacobian = 0;
};

// Most refractions a chain may have before it: the chain needs depth + vertices < max_depth so
// that the same path sampled by the BSDF would not have been cut short (MIS's weights).
inline constexpr int kMaxChainVertices = 2;

// Whether the scene has a solid with a smooth dielectric boundary, the only thing manifold
// next-event estimation looks through.
bool has_dielectric_solid(const Scene& scene);

// The solid a chain from `start` to `target` goes through, and its number of refractions, from
// the straight ray between them: from inside a solid, that solid if the ray leaves it first
// (1); from outside, the dielectric solid the ray meets first (2). None when the straight ray
// meets anything else first, or nothing.
struct ChainShape {
  int solid = -1;
  int vertices = 0;
  double t_boundary = 0;  // the straight ray's distance to the boundary
};
std::optional<ChainShape> chain_shape(const Scene& scene, const ChainStart& start,
                                      const ChainTarget& target);

// Where the walk from start to target starts: the straight direction, or for one refraction
// a few fixed-point steps from it towards the chain; the distance along it to the boundary and,
// for two refractions, the length of its chord through the solid, which the integrator's choice
// to walk reads (manifold_light.h). Deterministic.
struct ChainSeed {
  Vec3 w;
  Vec3 x_first;  // where it meets the boundary first
  double t_first;
  double t_through;  // 0 for one refraction
};
ChainSeed seed_chain(const Scene& scene, const ChainStart& start, const ChainTarget& target,
                     const ChainShape& shape);

// The chain through shape's solid from start to target, by Newton's method on the first
// direction from the seed, on the generalized half vector's constraint at the last vertex; none
// if the walk fails (no convergence, a solution that does not refract, a boundary without a
// normal, a direction the start cannot scatter into). Occlusion of its segments by other
// surfaces is not tested here. Counts the walk, its Newton steps and whether it found a chain.
std::optional<SpecularChain> solve_chain(const Scene& scene, const ChainStart& start,
                                         const ChainTarget& target, const ChainShape& shape,
                                         const ChainSeed& seed, ManifoldCounters& counters);

// Whether two unit directions are the same chain's: the walk converges far tighter than this.
bool same_direction(const Vec3& a, const Vec3& b);

}  // namespace nimbus
