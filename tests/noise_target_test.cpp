// Rendering to a noise target (render/noise_target.h, issue 45): the pass ends, the half sums,
// the error estimate against the known error of the mean, the same bits for any threads and any
// split of the work, blocks stopping where the rule says, and no bias between blocks that stop
// early and blocks that run long in a scene whose every pixel has a known mean.

#include "nimbus/render/noise_target.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "nimbus/render/path_sampler.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace nimbus {
namespace noise_target_test {

// A sphere of non-absorbing fog under a uniform sky of radiance 1: every pixel's mean is exactly
// 1 (nothing is absorbed, and the sky is the same in every direction), while the samples of
// pixels that see the fog vary (the sky's light reaches a scattering point by next-event
// estimation and by phase sampling, weighted by MIS) and those of the sky alone do not.
constexpr const char* kFurnace = R"({
  "film": {"width": 64, "height": 64},
  "camera": {"type": "perspective", "from": [0, 0, 5], "to": [0, 0, 0], "fov": 30},
  "integrator": {"spp": 1024, "seed": 3, "sampler": "independent", "noise_target": 0.03},
  "lights": [{"type": "environment", "radiance": [1, 1, 1]}],
  "media": {"fog": {"sigma_a": 0, "sigma_s": 1.5, "density": {"type": "field"}}},
  "objects": [{"shape": {"type": "sphere", "center": [0, 0, 0], "radius": 1.2}, "medium": "fog"}]
})";

Scene furnace(const std::vector<std::string>& overrides = {}) {
  return compile_scene(load_scene_json(nlohmann::json::parse(kFurnace), "furnace", overrides));
}

void expect_same_film(const Film& a, const Film& b) {
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_TRUE(a.sum == b.sum);
  EXPECT_TRUE(a.aov.half == b.aov.half);
}

TEST(NoiseTarget, PassEndsGrowByAQuarterAndEndAtTheCap) {
  const NoiseRule rule{0.01, 16, 300};
  std::vector<int> ends;
  for (int n = 0; n < rule.cap; n = next_pass_end(rule, n)) ends.push_back(next_pass_end(rule, n));
  const std::vector<int> expected = {16, 32, 48, 64, 80, 100, 124, 154, 192, 240, 300};
  EXPECT_EQ(ends, expected);
  for (int n = 1; n <= rule.cap; ++n)
    EXPECT_EQ(is_pass_end(rule, n), std::count(ends.begin(), ends.end(), n) == 1) << n;
  // An odd minimum is rounded up, so that every decision sees whole pairs.
  EXPECT_EQ(next_pass_end({0.01, 5, 100}, 0), 6);
  EXPECT_EQ(next_pass_end({0.01, 16, 10}, 0), 10);
}

// With a noise target the even and the odd samples are two randomizations of the sequence:
// sample 2k + 1 takes the point of sample 2k under another scramble, and without one the
// samples are the sequence's as before.
TEST(NoiseTarget, EvenAndOddSamplesAreTwoRandomizationsOfTheSequence) {
  RenderSettings plain;
  plain.seed = 7;
  RenderSettings target = plain;
  target.noise_target = 0.01;
  const ZSobol zsobol(16, 16, plain.seed);
  for (uint64_t s = 0; s < 40; ++s) {
    const ZSobol::Key a = PathSampler::sequence_key(plain, zsobol, 3, 5, s);
    const ZSobol::Key b = zsobol.key(3, 5, s);
    EXPECT_EQ(a.index, b.index);
    EXPECT_EQ(a.seed, b.seed);
    const ZSobol::Key t = PathSampler::sequence_key(target, zsobol, 3, 5, s);
    EXPECT_EQ(t.index, zsobol.key(3, 5, s / 2).index);
    EXPECT_EQ(t.seed == zsobol.key(3, 5, s / 2).seed, s % 2 == 0);
    EXPECT_EQ(in_half(s), s % 2 == 1);
  }
}

// Samples of known variance: uniform in [0, 2] (mean 1, σ² = 1/3) in every channel.
TEST(NoiseTarget, TheBlockErrorEstimatesTheRelativeErrorOfTheMean) {
  const int n = 64;
  Film film(kNoiseBlock, kNoiseBlock, 0, {Aov::Half});
  for (int p = 0; p < film.pixels(); ++p) {
    Rng rng(11, uint64_t(p));
    for (int s = 0; s < n; ++s) {
      const Rgb v({2 * rng.uniform(), 2 * rng.uniform(), 2 * rng.uniform()});
      ASSERT_TRUE(film.add(p, v));
      if (in_half(uint64_t(s))) film.aov.half[size_t(p)] += to_fixed(v);
    }
  }
  const double expected = std::sqrt(1.0 / 3.0 / n);
  // 192 terms, each d²/4 a scaled χ² of one degree of freedom: the mean of their ratios to the
  // true variance has a standard deviation of √(2/192) = 0.10, e's half that; 4 of them.
  EXPECT_NEAR(block_error(film, noise_block(film, 0, 0)) / expected, 1.0, 4 * 0.051);
}

// Under the default ZSobol sampler, whose error falls faster than independent samples' would:
// in the fog, where every pixel's mean is 1, the estimate d²/4 summed over the pixels and
// channels equals the summed squared error (m − 1)² itself (some 1 200 pixels of one degree of
// freedom each, the channels alike: each sum has a standard deviation of about 4 %, their ratio
// 6 %; 4 of them). A variance of the samples would overstate it.
TEST(NoiseTarget, TheHalvesEstimateTheErrorOfTheMeanUnderQuasiMonteCarlo) {
  const Scene scene = furnace({"integrator.sampler=\"zsobol\"", "integrator.noise_target=1e-9",
                               "integrator.noise_min_spp=64", "integrator.spp=64"});
  const Film film = render(scene).film;
  double estimated = 0, actual = 0, sample_variance = 0;
  int pixels = 0;
  for (int p = 0; p < film.pixels(); ++p) {
    const double n = film.samples[size_t(p)];
    ASSERT_EQ(n, 64);
    if (film.variance_of_mean(p)[0] == 0) continue;  // the sky alone: exact
    ++pixels;
    for (int c = 0; c < 3; ++c) {
      const double half_d =
          from_fixed(2 * film.aov.half[size_t(p)].c[c] - film.sum[size_t(p)].c[c], film.exponent) /
          n;
      estimated += half_d * half_d;
      actual += (film.mean(p)[c] - 1) * (film.mean(p)[c] - 1);
      sample_variance += film.variance_of_mean(p)[c];
    }
  }
  ASSERT_GT(pixels, 1000);
  EXPECT_NEAR(estimated / actual, 1.0, 0.25)
      << "sample variance / actual " << sample_variance / actual;
}

TEST(NoiseTarget, BlocksStopAtTheTargetOrTheCap) {
  const Scene scene = furnace();
  const RenderResult r = render(scene);
  const NoiseRule rule = noise_rule(scene.settings);
  std::set<uint32_t> counts;
  for (int by = 0; by < 8; ++by)
    for (int bx = 0; bx < 8; ++bx) {
      const NoiseBlock b = noise_block(r.film, bx, by);
      const uint32_t n = r.film.samples[size_t(b.y0) * 64 + b.x0];
      counts.insert(n);
      EXPECT_TRUE(block_done(rule, r.film, b)) << bx << ", " << by;
      EXPECT_TRUE(is_pass_end(rule, int(n)));
      if (int(n) < rule.cap) {
        EXPECT_LE(block_error(r.film, b), rule.target);
      }
    }
  // The sky's corners are exact and stop at the first decision; the fog's blocks take more, and
  // not all the same.
  EXPECT_EQ(r.film.samples[0], 16u);
  EXPECT_GE(counts.size(), 4u);
  EXPECT_GT(*counts.rbegin(), 100u);
  const NoiseProgress p = noise_progress(rule, r.film);
  EXPECT_EQ(p.converged, 1.0);
  EXPECT_EQ(p.fraction, 1.0);
}

TEST(NoiseTarget, TheSameBitsForAnyThreadsAndAnySplitOfTheWork) {
  const Scene scene = furnace({"film.width=40", "film.height=24", "integrator.spp=200"});
  RenderOptions one;
  one.threads = 1;
  const Film a = render(scene, one).film;
  RenderOptions two;
  two.threads = 2;
  expect_same_film(render(scene, two).film, a);

  // Samples [0, 37) and then the rest (37 is no pass end), and the image in two halves.
  Film b = make_film(scene);
  two.range.s1 = 37;
  render_into(scene, b, two);
  two.range = {0, 0, -1, -1, 37, -1};
  render_into(scene, b, two);
  expect_same_film(b, a);
  Film c = make_film(scene);
  render_into(scene, c, {2, {}, {0, 0, 16, 24, 0, -1}, {}});
  render_into(scene, c, {2, {}, {16, 0, 40, 24, 0, -1}, {}});
  expect_same_film(c, a);
}

TEST(NoiseTarget, RangesMustCoverWholeBlocksThatContinue) {
  const Scene scene = furnace({"film.width=20", "film.height=12"});
  Film film = make_film(scene);
  EXPECT_THROW(render_into(scene, film, {1, {}, {4, 0, 20, 12, 0, 4}, {}}), std::invalid_argument);
  EXPECT_THROW(render_into(scene, film, {1, {}, {0, 0, 12, 12, 0, 4}, {}}), std::invalid_argument);
  render_into(scene, film, {1, {}, {0, 0, 8, 8, 0, 4}, {}});
  // A block must continue from the count it holds, and start from 0.
  EXPECT_THROW(render_into(scene, film, {1, {}, {0, 0, 8, 8, 6, 8}, {}}), std::invalid_argument);
  EXPECT_THROW(render_into(scene, film, {1, {}, {8, 0, 16, 8, 4, 8}, {}}), std::invalid_argument);
  // A film without the half sums.
  Film plain(20, 12, scene.film_exponent);
  try {
    render_into(scene, plain, {1, {}, {}, {}});
    ADD_FAILURE() << "a film without half sums was rendered into";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("half sums"), std::string::npos) << e.what();
  }
}

// Every pixel's mean is 1. The blocks of the fog stop at different counts; those that stop early
// and those that run long must each average 1 within 4 standard errors: the stopping rule must
// not pick bright or dark blocks. The standard errors come from the film's sums of squares (the
// sampler is independent, so that they are the error's).
TEST(NoiseTarget, BlocksThatStopEarlyAreNeitherBrighterNorDarkerThanThoseThatRunLong) {
  const Scene scene = furnace({"integrator.noise_target=0.02", "integrator.spp=2048"});
  const RenderResult r = render(scene);
  std::vector<int> fog;  // pixels of blocks that took more than the first pass
  for (int p = 0; p < r.film.pixels(); ++p)
    if (r.film.samples[size_t(p)] > 16) fog.push_back(p);
  ASSERT_GT(fog.size(), 1000u);
  std::vector<uint32_t> counts;
  for (int p : fog) counts.push_back(r.film.samples[size_t(p)]);
  std::nth_element(counts.begin(), counts.begin() + counts.size() / 2, counts.end());
  const uint32_t median = counts[counts.size() / 2];
  std::vector<int> early, late;
  for (int p : fog) (r.film.samples[size_t(p)] <= median ? early : late).push_back(p);
  ASSERT_GT(early.size(), 200u);
  ASSERT_GT(late.size(), 200u);
  for (const auto* group : {&early, &late, &fog}) {
    const MeanEstimate m = region_mean(r.film, *group);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(m.mean[c], 1.0, 4 * m.standard_error[c])
          << group->size() << " pixels, standard error " << m.standard_error[c];
  }
}

}  // namespace noise_target_test
}  // namespace nimbus
