#include "nimbus/media/medium_field.h"

#include <algorithm>
#include <cmath>

#include "nimbus/frep/quadric.h"

namespace nimbus {

double medium_density(const Medium& medium, const Vec3& x, double F) {
  return medium.scale * medium.density->value(x, F);
}

bool add_span(MediumIntervals& m, double a, double b) {
  // Spans [i, j) overlap or touch [a, b]: they merge with it into one span at i, in place.
  int i = 0;
  while (i < m.count && m.spans[i].t1 < a) ++i;
  int j = i;
  for (; j < m.count && m.spans[j].t0 <= b; ++j) {
    a = std::min(a, m.spans[j].t0);
    b = std::max(b, m.spans[j].t1);
  }
  const int count = m.count + 1 - (j - i);
  if (count > MediumIntervals::kMax) return false;
  Span* const spans = m.spans.data();
  if (j == i)
    std::copy_backward(spans + j, spans + m.count, spans + count);
  else
    std::copy(spans + j, spans + m.count, spans + i + 1);
  spans[i] = {a, b};
  m.count = count;
  return true;
}

void drop_spans_before(MediumIntervals& m, double t) {
  int first = 0;
  while (first < m.count && m.spans[first].t1 <= t) ++first;
  std::copy(m.spans.begin() + first, m.spans.begin() + m.count, m.spans.begin());
  m.count -= first;
}

namespace {

// One quadric's stretches with F > 0 over [a, b], from both its roots at once (the general
// search below finds one root per first_hit and evaluates the tape between them). Roots are
// taken from a, as first_hit does, to keep their precision.
bool add_quadric_spans(const Quadric& quadric, const Ray& ray, double a, double b,
                       MediumIntervals& m) {
  const RayQuadratic F = restrict_to_ray(quadric, Ray{ray.at(a), ray.d});
  double roots[2];
  const int count = sign_change_roots(F, roots);
  double cuts[4] = {0};
  int n = 1;
  for (int i = 0; i < count; ++i)
    if (roots[i] > 0 && roots[i] < b - a) cuts[n++] = roots[i];
  cuts[n++] = b - a;
  for (int i = 0; i + 1 < n; ++i)
    if (F.at(0.5 * (cuts[i] + cuts[i + 1])) > 0 && !add_span(m, a + cuts[i], a + cuts[i + 1]))
      return false;
  return true;
}

}  // namespace

bool add_object_spans(const Tape& tape, const Box& bounds, const Ray& ray, double t0, double t1,
                      MediumIntervals& m) {
  double a = t0, b = t1;
  if (!clip_ray(bounds, ray, a, b) || !(b > a)) return true;
  if (tape.kind == TapeKind::SingleQuadric && std::isfinite(b))
    return add_quadric_spans(tape.quadrics[0], ray, a, b, m);
  // Right after a root, first_hit may find the same root again, a few ulps on (a path that
  // scatters just inside the surface starts there): the next search starts this far past it.
  // A stretch is told inside or outside at its midpoint, so only a sliver thinner than this
  // between two roots could be missed.
  const double skip = kRootSkip * length(bounds.extent());
  double t = a;  // the start of the current stretch: t0 or the last root
  for (int step = 0; step < 4 * MediumIntervals::kMax; ++step) {
    const double from = step == 0 ? a : t + skip;
    const std::optional<double> r =
        from < b ? first_hit(tape, ray, from, b) : std::optional<double>();
    const double end = r ? std::max(*r, from) : b;
    if (end > t && evaluate(tape, ray.at(0.5 * (t + end))) > 0 && !add_span(m, t, end))
      return false;
    if (!r) return true;
    t = end;
  }
  return add_span(m, t, b);  // more roots than spans allow: keep the rest, conservatively
}

}  // namespace nimbus
