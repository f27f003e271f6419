// The skip criterion of the render tests (support/weight_growth.h) against second moments worked
// out by hand, so that a test is skipped for the reason its message gives.

#include "support/weight_growth.h"

#include <gtest/gtest.h>

namespace nimbus {
namespace weight_growth_test {

using test::medium_growth;

TEST(WeightGrowth, MaxRuleInAChromaticFurnace) {
  // sigma_s = (1, 3, 6), albedo 1, mu_bar = 6: x_s = 6, x_n = 5, c = 11; channel 2 has no null
  // coefficient, so rho = (11/36) · 36/6 = 11/6; channel 0: (11/36)(1/6 + 25/5) = 1.578.
  for (bool collide : {true, false})
    EXPECT_NEAR(medium_growth(EventRule::Max, {0, 0, 0}, {1, 3, 6}, true, 1, false, collide),
                11.0 / 6, 1e-12);
}

TEST(WeightGrowth, MaxRuleInChandrasekharsHalfSpace) {
  // mu_t = mu_bar = 1, albedos (0.3, 0.7, 0.95): with absorption events c = 0.7 + 0.95 and
  // rho = c ω²/0.95 = 1.5675 at ω = 0.95; without, every collision scatters and rho = ω².
  const test::Channels a = {0.7, 0.3, 0.05}, s = {0.3, 0.7, 0.95};
  EXPECT_NEAR(medium_growth(EventRule::Max, a, s, true, 1, false, true), 1.65 * 0.95, 1e-12);
  EXPECT_NEAR(medium_growth(EventRule::Max, a, s, true, 1, false, false), 0.95 * 0.95, 1e-12);
}

TEST(WeightGrowth, DeltaTrackingWithABoundingMajorantNeverGrows) {
  // Channel rule, bounded: rho = (mu_s + mu_n)/mu_bar <= 1 at every density.
  const test::Channels a = {0.2, 0.05, 0.4}, s = {4, 12, 8};
  for (bool collide : {true, false})
    for (bool decomposition : {false, true}) {
      const double rho = medium_growth(EventRule::Channel, a, s, false, 1, decomposition, collide);
      EXPECT_LE(rho, 1 + 1e-12);
      EXPECT_GT(rho, 0.9);
    }
  // Scaled by 0.5 in an albedo-1 medium: c = 1.5 mu_t, mu_s + |mu_n| = 1.5 mu_t, R = mu_t / 2.
  EXPECT_NEAR(medium_growth(EventRule::Channel, {0, 0, 0}, {2, 2, 2}, true, 0.5, false, true), 9,
              1e-12);
}

}  // namespace weight_growth_test
}  // namespace nimbus
