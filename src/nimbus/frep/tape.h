#pragma once
// A shape compiled to a flat instruction tape (as libfive does): transforms are folded into
// world-space quadric coefficients, and the tree becomes a register program that evaluates
// F (> 0 inside) at a point, over a box, or along a ray, with one template interpreter
// (tape_eval.h).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "nimbus/frep/bounds.h"
#include "nimbus/frep/quadric.h"
#include "nimbus/frep/shape_desc.h"
#include "nimbus/math/box.h"
#include "nimbus/math/interval.h"
#include "nimbus/math/vec3.h"

namespace nimbus {

// Registers are the nesting depth of the tree; this many suffice for any sane scene.
constexpr int kMaxRegisters = 32;
// A free form with more quadric perturbations than this is intersected by the general path.
constexpr int kMaxFlatPerturbations = 64;

enum class Op : std::uint8_t {
  Quadric,     // r[dst] = quadrics[quadric](x)
  Max,         // r[dst] = max(r[dst], r[src])           (union)
  Min,         // r[dst] = min(r[dst], r[src])           (intersection, difference)
  Neg,         // r[dst] = −r[dst]                        (difference's subtrahends)
  AddCubePos,  // r[dst] += weight · max(r[src], 0)³     (a perturbation, eq. 1–2)
};

struct Instr {
  Op op = Op::Quadric;
  std::uint16_t dst = 0;
  std::uint16_t src = 0;
  std::uint32_t quadric = 0;
  double weight = 0;
};

enum class TapeKind : std::uint8_t {
  SingleQuadric,  // one quadric: analytic roots
  FlatFreeForm,   // quadric base + quadric perturbations: piecewise polynomial of degree <= 6
  QuadricCsg,     // union / intersection / difference of quadrics: crossings at leaf roots
  General,        // anything else: interval subdivision along the ray
};

struct Tape {
  std::vector<Quadric> quadrics;  // world space
  std::vector<Instr> code;        // the result is register 0
  int num_registers = 0;
  TapeKind kind = TapeKind::General;
  // FlatFreeForm only: quadrics[0] is the base, quadrics[i + 1] has weight weights[i].
  std::vector<double> weights;
  // Per quadric: 1 when its value is used only as a perturbation max(q, 0)³, so that where
  // q <= 0 nothing else about it matters.
  std::vector<std::uint8_t> only_cubed;
  // Per quadric: whether interval evaluation may enclose it by [-inf, 0] where it is <= 0 (not
  // for a difference's subtrahend outside perturbations, whose lower bound matters).
  std::vector<std::uint8_t> cullable;
  // Per quadric that is only cubed or cullable: a box outside which it is <= 0 (quadric_box
  // grown by a relative 1e-9), so that interval evaluation over a box elsewhere skips it: a free
  // form's perturbations and a large union's children are mostly small and far apart.
  // Everything for the others.
  std::vector<Box> cull_box;
  Bounds bounds;
  // Where first_hit looks: the bounds padded against round-off, or, for an unbounded shape,
  // its box cut to |x_i| <= kUnboundedExtent (the scene loader clips those anyway).
  Box search_box;
  // A length for tolerances: the search box's diagonal.
  double size = 1;
};

constexpr double kUnboundedExtent = 1e6;

// The most quadrics one tape may hold. A shape used twice is compiled twice, so a few named
// shapes that each use the previous one twice describe 2^k quadrics: the limit keeps such a file
// from exhausting memory and time. A free form of 10 000 scattered perturbations loads and
// renders a tiny image in 1 s; coincident quadrics are the worst case (interval evaluation cannot
// skip any of them): 8 192 coincident spheres take 9 s.
constexpr std::size_t kMaxTapeQuadrics = 20000;

// The quadrics compile() would emit for the shape, counting shared sub-shapes once per use;
// the count stops just above `cap` (so any shape is counted quickly).
std::size_t count_quadrics(const ShapeDesc& shape, std::size_t cap = kMaxTapeQuadrics);

// Whether the caller reads F's value (a density that grows with F) or only its sign (the
// surface). With Sign, a quadric whose value feeds only unions, intersections and differences is
// normalised (quadric.h): the same surface, but coefficients of any finite magnitude are
// intersected without overflow. A free form's sum reads F's value (a perturbation of weight w
// adds to F), so the quadrics in one are kept as given.
enum class FUse { Value, Sign };

// Throws std::invalid_argument on a null shape, an empty CSG node, nesting deeper than
// kMaxRegisters or more than kMaxTapeQuadrics quadrics; otherwise assumes a valid tree (the
// scene loader checks it).
Tape compile(const ShapeDesc& shape, FUse use = FUse::Value);

// compile(shape) placed by `placement` (applied after the shape's own transform; the same tape,
// bit for bit, as compile of the shape wrapped in that transform: only the coefficients
// transform), with bounds carried from `local`, the unplaced shape's (placed_bounds in
// bounds.h) instead of searched: a shape used by many objects is searched once.
Tape compile_placed(const ShapeDesc& shape, const Mat4& placement, FUse use, const Bounds& local);

double evaluate(const Tape& tape, const Vec3& p);     // F(p), > 0 inside
Vec3 gradient(const Tape& tape, const Vec3& p);       // ∇F(p), forward mode; points inward
Interval evaluate(const Tape& tape, const Box& box);  // encloses F over the box

}  // namespace nimbus
