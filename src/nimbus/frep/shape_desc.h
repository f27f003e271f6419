#pragma once
// The description of a shape as the scene file states it: a tree of quadrics, free forms
// (paper eq. 1–2) and CSG, each node with its own transform. Plain data; compile() in
// tape.h turns it into the flat run-time form.

#include <memory>
#include <variant>
#include <vector>

#include "nimbus/frep/quadric.h"
#include "nimbus/math/mat4.h"

namespace nimbus {

struct ShapeDesc;
using ShapePtr = std::shared_ptr<const ShapeDesc>;

struct QuadricNode {
  Quadric q;
};

struct Perturbation {
  ShapePtr shape;
  double weight = 0;  // f_i: positive adds material, negative carves
};

// F' = F_base + Σ f_i R_i,  R_i = max(F_i, 0)³  (eq. 1–2). Any shape may be base or perturbation.
struct FreeFormNode {
  ShapePtr base;
  std::vector<Perturbation> perturbations;
};

enum class CsgOp { Union, Intersection, Difference };

// Union: max of the children; intersection: min; difference: min(F_0, -F_1, -F_2, ...).
struct CsgNode {
  CsgOp op = CsgOp::Union;
  std::vector<ShapePtr> children;
};

struct ShapeDesc {
  std::variant<QuadricNode, FreeFormNode, CsgNode> node;
  // Object-to-world transform of this node and everything under it.
  Mat4 transform = Mat4::identity();
};

inline ShapePtr make_shape(QuadricNode n, const Mat4& m = Mat4::identity()) {
  return std::make_shared<ShapeDesc>(ShapeDesc{std::move(n), m});
}
inline ShapePtr make_shape(FreeFormNode n, const Mat4& m = Mat4::identity()) {
  return std::make_shared<ShapeDesc>(ShapeDesc{std::move(n), m});
}
inline ShapePtr make_shape(CsgNode n, const Mat4& m = Mat4::identity()) {
  return std::make_shared<ShapeDesc>(ShapeDesc{std::move(n), m});
}
inline ShapePtr with_transform(const ShapePtr& s, const Mat4& m) {
  auto copy = std::make_shared<ShapeDesc>(*s);
  copy->transform = m * copy->transform;
  return copy;
}

}  // namespace nimbus
