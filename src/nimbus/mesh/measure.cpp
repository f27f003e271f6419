#include "nimbus/mesh/measure.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "nimbus/frep/intersect.h"
#include "nimbus/math/rng.h"

namespace nimbus {

double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // The regions of the plane: beyond a vertex, beyond an edge, or inside (Ericson, Real-Time
  // Collision Detection 5.1.5).
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return length(ap);
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return length(bp);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return length(p - (a + ab * (d1 / (d1 - d3))));
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return length(cp);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return length(p - (a + ac * (d2 / (d2 - d6))));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  const double s = 1 / (va + vb + vc);
  return length(p - (a + ab * (vb * s) + ac * (vc * s)));
}

std::vector<Vec3> surface_samples(const Tape& tape, int count, std::uint64_t seed) {
  const Box b = tape.bounds.box;
  const Vec3 centre = b.center();
  const double r = length(b.extent());
  Rng rng(seed, 0);
  std::vector<Vec3> out;
  while (int(out.size()) < count) {
    // A uniform direction (z uniform in [−1, 1], φ uniform) for the ray's start.
    const double z = 1 - 2 * rng.uniform(), phi = 2 * std::numbers::pi * rng.uniform();
    const double s = std::sqrt(std::max(0.0, 1 - z * z));
    const Vec3 from = centre + Vec3{s * std::cos(phi), s * std::sin(phi), z} * r;
    const Vec3 to = centre + Vec3{rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5} *
                                 (0.5 * r / std::sqrt(3.0));
    const Vec3 d = normalize(to - from);
    if (const auto t = first_hit(tape, Ray{from, d}, 0, 2 * r)) out.push_back(from + d * *t);
  }
  return out;
}

}  // namespace nimbus
