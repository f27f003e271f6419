#pragma once
// Per-pixel chi-square of a render against a reference image or against an independent render:
// the sum over pixel-channels of squared z-scores, chi-square distributed with one degree of
// freedom per pixel-channel when both estimate the same image.

#include <cmath>
#include <functional>
#include <limits>

#include "nimbus/render/film.h"
#include "stats.h"

namespace nimbus::test {

struct Chi2 {
  double value = 0;
  int dof = 0;
  // Below the critical value at upper-tail probability p (1e-4: a false alarm in 10 000 runs).
  bool passes(double p = 1e-4) const { return dof > 0 && value < chi_square_critical(dof, p); }
};

// Pixel-channels where the estimate has no variance (no path met anything that varies) must
// equal the reference to rounding; any other difference there makes the sum infinite.
inline void add_z(Chi2& c, double diff, double var) {
  if (var > 0) {
    c.value += diff * diff / var;
    ++c.dof;
  } else if (std::abs(diff) > 1e-12) {
    c.value = std::numeric_limits<double>::infinity();
  }
}

// Two independent renders of the same expected image.
inline Chi2 film_chi2(const Film& a, const Film& b) {
  Chi2 c;
  for (int p = 0; p < a.width * a.height; ++p) {
    const Rgb va = a.variance_of_mean(p), vb = b.variance_of_mean(p);
    for (int ch = 0; ch < 3; ++ch) add_z(c, a.mean(p)[ch] - b.mean(p)[ch], va[ch] + vb[ch]);
  }
  return c;
}

// As film_chi2 of two renders, over blocks of k × k pixels (the films' sizes multiples of k):
// each z-score then rests on k² times the samples, which keeps it near normal where single
// pixels' estimates are heavy-tailed (weighted trackers' rare large weights) and their sample
// variances too unreliable for the per-pixel sum to be chi-square distributed.
inline Chi2 film_chi2_blocks(const Film& a, const Film& b, int k) {
  Chi2 c;
  for (int by = 0; by + k <= a.height; by += k)
    for (int bx = 0; bx + k <= a.width; bx += k) {
      Rgb diff(0.0), var(0.0);
      for (int y = by; y < by + k; ++y)
        for (int x = bx; x < bx + k; ++x) {
          const int p = y * a.width + x;
          diff += (a.mean(p) - b.mean(p)) / double(k * k);
          var += (a.variance_of_mean(p) + b.variance_of_mean(p)) / double(k * k * k * k);
        }
      for (int ch = 0; ch < 3; ++ch) add_z(c, diff[ch], var[ch]);
    }
  return c;
}

// A render against reference pixel values ref(pixel) (exact, or of negligible error), over the
// pixels where use(pixel) holds (all by default).
inline Chi2 film_chi2(const Film& a, const std::function<Rgb(int)>& ref,
                      const std::function<bool(int)>& use = {}) {
  Chi2 c;
  for (int p = 0; p < a.width * a.height; ++p) {
    if (use && !use(p)) continue;
    const Rgb va = a.variance_of_mean(p), r = ref(p);
    for (int ch = 0; ch < 3; ++ch) add_z(c, a.mean(p)[ch] - r[ch], va[ch]);
  }
  return c;
}

}  // namespace nimbus::test
