#pragma once
// An allowed interval for a number; each end may be open, closed or absent. The scene format's
// values and the render settings' declarations (render/settings.h) state their ranges with it.

#include <fmt/format.h>

#include <cstdlib>
#include <optional>
#include <string>

namespace nimbus {

struct Range {
  std::optional<double> lo, hi;
  bool lo_open = false, hi_open = false;
};
inline Range at_least(double lo) {
  return {lo, {}, false, false};
}
inline Range above(double lo) {
  return {lo, {}, true, false};
}
inline Range between(double lo, double hi) {
  return {lo, hi, false, false};
}  // [lo, hi]
inline Range strictly_between(double lo, double hi) {
  return {lo, hi, true, true};
}  // (lo, hi)

inline bool contains(const Range& r, double x) {
  if (r.lo && (r.lo_open ? !(x > *r.lo) : !(x >= *r.lo))) return false;
  if (r.hi && (r.hi_open ? !(x < *r.hi) : !(x <= *r.hi))) return false;
  return true;
}

// "in [1, 16384]", ">= 1", "> 0"; "" for no bound.
// x in its shortest round-trip form, or past ten characters in %g where that is exact: 1e+15
// rather than 1000000000000000; 1000000, 16384 and 0.85 as they are.
inline std::string bound_text(double x) {
  std::string shortest = fmt::format("{}", x), g = fmt::format("{:g}", x);
  return shortest.size() > 10 && std::strtod(g.c_str(), nullptr) == x ? g : shortest;
}

inline std::string range_text(const Range& r) {
  if (r.lo && r.hi)
    return fmt::format("in {}{}, {}{}", r.lo_open ? "(" : "[", bound_text(*r.lo), bound_text(*r.hi),
                       r.hi_open ? ")" : "]");
  if (r.lo) return fmt::format("{} {}", r.lo_open ? ">" : ">=", bound_text(*r.lo));
  if (r.hi) return fmt::format("{} {}", r.hi_open ? "<" : "<=", bound_text(*r.hi));
  return "";
}

}  // namespace nimbus
