#pragma once
// Comparing two renders of the same scene by two estimators: per 8 × 8 block of pixels, their
// means must agree within 4 standard errors of the difference (the blocks' variances from the
// per-pixel sample variances; the two renders' samples are independent).

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "nimbus/render/film.h"

namespace nimbus::test {

// The pixels of the 8 × 8 block whose corner is (bx, by) in a size × size film.
inline std::vector<int> block_pixels(int bx, int by, int size) {
  std::vector<int> pixels;
  for (int y = by; y < by + 8; ++y)
    for (int x = bx; x < bx + 8; ++x) pixels.push_back(y * size + x);
  return pixels;
}

inline void expect_blocks_agree(const Film& a, const Film& b, int size, const char* what) {
  ASSERT_EQ(size % 8, 0);
  int compared = 0;
  for (int by = 0; by < size; by += 8)
    for (int bx = 0; bx < size; bx += 8) {
      const std::vector<int> pixels = block_pixels(bx, by, size);
      const MeanEstimate ma = region_mean(a, pixels), mb = region_mean(b, pixels);
      for (int c = 0; c < 3; ++c) {
        const double se = std::hypot(ma.standard_error[c], mb.standard_error[c]);
        EXPECT_NEAR(ma.mean[c], mb.mean[c], 4 * se + 1e-12)
            << what << ": block (" << bx << ", " << by << ") channel " << c << ", SE " << se;
        ++compared;
      }
    }
  EXPECT_EQ(compared, size * size / 64 * 3);
}

}  // namespace nimbus::test
