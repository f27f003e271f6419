#include "nimbus/frep/tape.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>
#include <variant>

#include "nimbus/frep/tape_eval.h"

namespace nimbus {
namespace {

class Compiler {
 public:
  Compiler(Tape& tape, FUse use) : tape_(tape), use_(use) {}

  // Emits code leaving the node's F in register `reg`, with registers above it as scratch.
  // `parent` is the composed object-to-world transform of the node's ancestors.
  void emit(const ShapeDesc& shape, const Mat4& parent, int reg) {
    if (reg >= kMaxRegisters) throw std::invalid_argument("compile: shape nested too deeply");
    tape_.num_registers = std::max(tape_.num_registers, reg + 1);
    const Mat4 world = parent * shape.transform;
    std::visit([&](const auto& node) { emit_node(node, world, reg); }, shape.node);
  }

 private:
  void emit_child(const ShapePtr& child, const Mat4& world, int reg) {
    if (!child) throw std::invalid_argument("compile: null shape");
    emit(*child, world, reg);
  }

  void emit_node(const QuadricNode& node, const Mat4& world, int reg) {
    const auto index = static_cast<std::uint32_t>(tape_.quadrics.size());
    // Only the sign matters here: normalise before the transform (its products must not
    // overflow) and after it (it may scale the coefficients far from 1).
    const bool sign_only = use_ == FUse::Sign && summed_depth_ == 0;
    tape_.quadrics.push_back(sign_only ? normalised(transformed(normalised(node.q), world))
                                       : transformed(node.q, world));
    // Where a quadric is <= 0, [-inf, 0] encloses it. That keeps what unions and intersections
    // need (the sign of the upper bound) but not what a sum needs (how far below 0 a free form's
    // base lies, which perturbations must overcome) nor what negation turns into the upper bound.
    tape_.cullable.push_back(!negated_ && summed_depth_ == 0);
    push({Op::Quadric, reg16(reg), 0, index, 0});
  }

  void emit_node(const FreeFormNode& node, const Mat4& world, int reg) {
    ++summed_depth_;
    emit_child(node.base, world, reg);
    --summed_depth_;
    for (const Perturbation& p : node.perturbations) {
      if (!p.shape) throw std::invalid_argument("compile: null perturbation");
      // A zero weight leaves F unchanged (eq. 1); do not pay for it.
      if (p.weight == 0) continue;
      ++summed_depth_;
      emit(*p.shape, world, reg + 1);
      --summed_depth_;
      push({Op::AddCubePos, reg16(reg), reg16(reg + 1), 0, p.weight});
    }
  }

  void emit_node(const CsgNode& node, const Mat4& world, int reg) {
    if (node.children.empty()) throw std::invalid_argument("compile: empty CSG node");
    emit_child(node.children[0], world, reg);
    for (size_t i = 1; i < node.children.size(); ++i) {
      const bool subtrahend = node.op == CsgOp::Difference;
      negated_ ^= subtrahend;
      emit_child(node.children[i], world, reg + 1);
      negated_ ^= subtrahend;
      switch (node.op) {
        case CsgOp::Union:
          push({Op::Max, reg16(reg), reg16(reg + 1), 0, 0});
          break;
        case CsgOp::Intersection:
          push({Op::Min, reg16(reg), reg16(reg + 1), 0, 0});
          break;
        case CsgOp::Difference:
          push({Op::Neg, reg16(reg + 1), 0, 0, 0});
          push({Op::Min, reg16(reg), reg16(reg + 1), 0, 0});
          break;
      }
    }
  }

  static std::uint16_t reg16(int reg) { return static_cast<std::uint16_t>(reg); }
  void push(const Instr& in) { tape_.code.push_back(in); }

  Tape& tape_;
  FUse use_;
  bool negated_ = false;  // the node being emitted is negated (an odd number of times)
  int summed_depth_ = 0;  // how many free forms' sums (base or perturbation) the node lies in
};

// FlatFreeForm: Quadric(r0) followed by pairs Quadric(r1), AddCubePos(r0 += w · r1).
// QuadricCsg: no AddCubePos at all.
TapeKind classify(const std::vector<Instr>& code) {
  if (code.size() == 1) return TapeKind::SingleQuadric;
  if (std::none_of(code.begin(), code.end(),
                   [](const Instr& in) { return in.op == Op::AddCubePos; }))
    return TapeKind::QuadricCsg;
  const size_t perturbations = (code.size() - 1) / 2;
  if (code.size() % 2 == 0 || perturbations > kMaxFlatPerturbations) return TapeKind::General;
  for (size_t i = 0; i < perturbations; ++i) {
    const Instr& load = code[1 + 2 * i];
    const Instr& add = code[2 + 2 * i];
    if (load.op != Op::Quadric || load.dst != 1 || add.op != Op::AddCubePos || add.dst != 0 ||
        add.src != 1)
      return TapeKind::General;
  }
  return TapeKind::FlatFreeForm;
}

// Marks the quadrics whose value is only ever cubed: the emitter consumes a perturbation's
// register right after loading it and never reads it again.
std::vector<std::uint8_t> only_cubed(const Tape& tape) {
  std::vector<std::uint8_t> marks(tape.quadrics.size(), 0);
  for (size_t k = 0; k + 1 < tape.code.size(); ++k) {
    const Instr &load = tape.code[k], &next = tape.code[k + 1];
    if (load.op == Op::Quadric && next.op == Op::AddCubePos && next.src == load.dst)
      marks[load.quadric] = 1;
  }
  return marks;
}

// The box grown on every side by `relative` times its diagonal (finite, non-empty boxes only).
Box grown(const Box& box, double relative) {
  if (box.empty() || !box.finite()) return box;
  const double pad = relative * length(box.extent()) + 1e-300;
  return {box.lo - Vec3{pad, pad, pad}, box.hi + Vec3{pad, pad, pad}};
}

// The box first_hit clips rays to: the bounds grown by a relative 1e-9 so that rounding in the
// clip never shaves off a crossing on a tight face, or a huge cube for unbounded shapes.
Box search_box(const Bounds& bounds) {
  const Box world{{-kUnboundedExtent, -kUnboundedExtent, -kUnboundedExtent},
                  {kUnboundedExtent, kUnboundedExtent, kUnboundedExtent}};
  if (!bounds.bounded) return intersect(bounds.box, world);
  if (bounds.box.empty()) return bounds.box;
  const double pad = 1e-9 * length(bounds.box.extent()) + 1e-300;
  return {bounds.box.lo - Vec3{pad, pad, pad}, bounds.box.hi + Vec3{pad, pad, pad}};
}

}  // namespace

namespace {

// Quadrics under s, memoised per node (named shapes are shared), saturating at cap + 1.
std::size_t count_quadrics(const ShapeDesc& s, std::size_t cap,
                           std::unordered_map<const ShapeDesc*, std::size_t>& memo) {
  if (const auto it = memo.find(&s); it != memo.end()) return it->second;
  std::size_t n = 0;
  const auto add = [&](const ShapePtr& child) {
    if (child) n = std::min(cap + 1, n + count_quadrics(*child, cap, memo));
  };
  if (std::holds_alternative<QuadricNode>(s.node)) {
    n = 1;
  } else if (const auto* ff = std::get_if<FreeFormNode>(&s.node)) {
    add(ff->base);
    for (const Perturbation& p : ff->perturbations) add(p.shape);
  } else {
    for (const ShapePtr& child : std::get<CsgNode>(s.node).children) add(child);
  }
  memo[&s] = n;
  return n;
}

}  // namespace

std::size_t count_quadrics(const ShapeDesc& shape, std::size_t cap) {
  std::unordered_map<const ShapeDesc*, std::size_t> memo;
  return count_quadrics(shape, cap, memo);
}

namespace {

// compile() up to the bounds, with the shape placed by `placement`.
Tape compile_code(const ShapeDesc& shape, const Mat4& placement, FUse use) {
  if (count_quadrics(shape) > kMaxTapeQuadrics)
    throw std::invalid_argument("compile: more than " + std::to_string(kMaxTapeQuadrics) +
                                " quadrics in one shape");
  Tape tape;
  Compiler(tape, use).emit(shape, placement, 0);
  tape.only_cubed = only_cubed(tape);
  tape.cull_box.assign(tape.quadrics.size(), Box::everything());
  for (size_t i = 0; i < tape.quadrics.size(); ++i)
    if (tape.only_cubed[i] || tape.cullable[i])
      tape.cull_box[i] = grown(quadric_box(tape.quadrics[i]), 1e-9);
  tape.kind = classify(tape.code);
  if (tape.kind == TapeKind::FlatFreeForm)
    for (size_t k = 2; k < tape.code.size(); k += 2) tape.weights.push_back(tape.code[k].weight);
  return tape;
}

void set_bounds(Tape& tape, const Bounds& bounds) {
  tape.bounds = bounds;
  tape.search_box = search_box(tape.bounds);
  const double diagonal = length(tape.search_box.extent());
  tape.size = std::isfinite(diagonal) && diagonal > 0 ? diagonal : 1.0;
}

}  // namespace

Tape compile(const ShapeDesc& shape, FUse use) {
  Tape tape = compile_code(shape, Mat4::identity(), use);
  set_bounds(tape, compute_bounds(tape));
  return tape;
}

Tape compile_placed(const ShapeDesc& shape, const Mat4& placement, FUse use, const Bounds& local) {
  Tape tape = compile_code(shape, placement, use);
  // One quadric's box is exact and cheap (no search): the same bounds as compile's.
  set_bounds(tape, tape.kind == TapeKind::SingleQuadric ? compute_bounds(tape)
                                                        : placed_bounds(tape, local, placement));
  return tape;
}

double evaluate(const Tape& tape, const Vec3& p) {
  return run_tape<double>(tape, [&](std::uint32_t i) { return tape.quadrics[i].eval_finite(p); });
}

Vec3 gradient(const Tape& tape, const Vec3& p) {
  return value_gradient(tape, p).grad;
}

Interval evaluate(const Tape& tape, const Box& box) {
  return run_tape<Interval>(tape, [&](std::uint32_t i) {
    // Over a box outside the quadric's positive set: a perturbation adds nothing, whatever its
    // value (0 says so), and anything else is enclosed by [-inf, 0] (see Compiler).
    if (intersect(tape.cull_box[i], box).empty())
      return tape.only_cubed[i] ? Interval::point(0) : Interval{-Box::kInf, 0.0};
    // Terms of opposite signs past a double's range (issue 44): nothing is known.
    const Interval range = quadric_range(tape.quadrics[i], box);
    return range.lo == range.lo && range.hi == range.hi ? range : Interval{-Box::kInf, Box::kInf};
  });
}

}  // namespace nimbus
