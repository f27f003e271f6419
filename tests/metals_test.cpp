// Named metals (spectral/metals.h): the tabulated curves, and rgb mode's η chosen so that the
// metal's head-on colour is the projection of its measured reflectance.

#include "nimbus/spectral/metals.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "nimbus/spectral/spectral_curve.h"

namespace nimbus {
namespace {

double normal_reflectance(double eta, double k) {
  return ((eta - 1) * (eta - 1) + k * k) / ((eta + 1) * (eta + 1) + k * k);
}

// Reflectance at normal incidence from the curves, sampled every nm, projected to RGB.
Rgb measured_colour(const Metal& m) {
  std::vector<std::pair<double, double>> r;
  for (double nm = 360; nm <= 830; nm += 1)
    r.emplace_back(nm, normal_reflectance((*m.eta.curve)(nm), (*m.k.curve)(nm)));
  return reflectance_to_rgb(piecewise_linear_spectrum(r));
}

TEST(Metals, RgbModeShowsTheMeasuredColourHeadOn) {
  for (const auto name : metal_names()) {
    SCOPED_TRACE(std::string(name));
    const auto m = metal_by_name(name);
    ASSERT_TRUE(m);
    ASSERT_TRUE(m->eta.curve && m->k.curve);
    const Rgb want = measured_colour(*m);
    for (int c = 0; c < 3; ++c) {
      // Gold's head-on red lies outside sRGB (1.04): rgb mode clamps it to 0.999.
      EXPECT_NEAR(normal_reflectance(m->eta.rgb[c], m->k.rgb[c]), std::min(want[c], 0.999), 5e-3)
          << c;
      EXPECT_GT(m->eta.rgb[c], 0);
    }
  }
  // Gold is yellow (red > green > blue) and silver nearly white and bright, from the data.
  const Rgb gold = measured_colour(*metal_by_name("gold"));
  EXPECT_GT(gold[0], gold[1]);
  EXPECT_GT(gold[1], gold[2]);
  const Rgb silver = measured_colour(*metal_by_name("silver"));
  EXPECT_GT(silver[2], 0.85);
  EXPECT_LT(silver[0] - silver[2], 0.1);
  // Johnson & Christy's gold at 0.5486 µm: n = 0.43, k = 2.455.
  const Metal au = *metal_by_name("gold");
  EXPECT_NEAR((*au.eta.curve)(548.6), 0.43, 1e-12);
  EXPECT_NEAR((*au.k.curve)(548.6), 2.455, 1e-12);
  EXPECT_FALSE(metal_by_name("brass"));
}

}  // namespace
}  // namespace nimbus
