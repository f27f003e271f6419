// The ZSobol sampler (math/zsobol.h): Sobol's first two dimensions, nets per pixel and per block
// of pixels, 1D stratification, decorrelated dimensions, determinism and range.

#include "nimbus/math/zsobol.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <vector>

#include "support/stats.h"

namespace nimbus {
namespace zsobol_test {

// Whether n = 2^m points put exactly one point in every elementary interval of area 1/n
// (2^a × 2^(m−a) cells, every a): a (0,m,2)-net in base 2.
bool is_net(const std::vector<std::array<double, 2>>& pts) {
  const int m = std::bit_width(pts.size()) - 1;
  if (size_t(1) << m != pts.size()) return false;
  for (int a = 0; a <= m; ++a) {
    std::vector<int> count(pts.size(), 0);
    for (const auto& p : pts) {
      const auto i = uint64_t(p[0] * double(uint64_t(1) << a));
      const auto j = uint64_t(p[1] * double(uint64_t(1) << (m - a)));
      if (++count[(i << (m - a)) | j] > 1) return false;
    }
  }
  return true;
}

// Whether n numbers put one in each of n equal intervals of [0, 1).
bool is_stratified(const std::vector<double>& xs) {
  std::vector<int> count(xs.size(), 0);
  for (double x : xs)
    if (++count[size_t(x * double(xs.size()))] > 1) return false;
  return true;
}

TEST(ZSobol, SobolDimensionsAreTheKnownSequences) {
  // Van der Corput: 0, 1/2, 1/4, 3/4, ...; Sobol's second dimension: 0, 1/2, 3/4, 1/4, 5/8, ...
  const double d0[] = {0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875};
  const double d1[] = {0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875};
  for (uint64_t i = 0; i < 8; ++i) {
    EXPECT_EQ(reversed_to_unit(sobol0_reversed(i)), d0[i]) << i;
    EXPECT_EQ(reversed_to_unit(sobol1_reversed(i)), d1[i]) << i;
  }
  // Unscrambled, every aligned block of 2^m is a (0,m,2)-net.
  for (uint64_t start : {0ull, 64ull, 1ull << 40}) {
    std::vector<std::array<double, 2>> pts;
    for (uint64_t i = start; i < start + 64; ++i)
      pts.push_back({reversed_to_unit(sobol0_reversed(i)), reversed_to_unit(sobol1_reversed(i))});
    EXPECT_TRUE(is_net(pts)) << start;
  }
}

TEST(ZSobol, IndexShuffleIsABijectionOntoBlocks) {
  // A 4 × 4 film (two base-4 digits) at 8 spp (three sample bits).
  const int pixel_bits = 4, sample_bits = 3;
  std::set<uint64_t> seen;
  for (uint64_t i = 0; i < 128; ++i) {
    const uint64_t p = shuffle_index(i, pixel_bits, sample_bits, 42);
    EXPECT_LT(p, 128u);
    seen.insert(p);
    // Every aligned block (2^j samples of a pixel, a pixel, a 2×2 quad) lands in one aligned
    // block of the same size.
    for (int j : {1, 2, 3, 5})
      EXPECT_EQ(p >> j, shuffle_index(i & ~((1ull << j) - 1), pixel_bits, sample_bits, 42) >> j)
          << i << ", block of 2^" << j;
  }
  EXPECT_EQ(seen.size(), 128u);
}

// Every pixel's samples, for spp a power of 2, are a net in each 2D dimension pair and
// stratified in every 1D dimension. (A 2×2 quad's are not a joint net: the pixel blocks are 2^16
// samples whatever the spp, so that samples do not depend on it; see zsobol.h.)
TEST(ZSobol, PixelSamplesAreNets) {
  for (int spp : {1, 2, 4, 8, 16, 32, 64, 256}) {
    const ZSobol z(37, 23, 7);
    for (auto [x, y] : {std::pair{0, 0}, std::pair{5, 3}, std::pair{36, 22}}) {
      for (uint32_t dim : {0u, 2u, 5u, 1000u}) {
        std::vector<std::array<double, 2>> pts;
        std::vector<double> line;
        for (int s = 0; s < spp; ++s) {
          pts.push_back(z.get2d(z.key(x, y, uint64_t(s)), dim));
          line.push_back(z.get1d(z.key(x, y, uint64_t(s)), dim + 1));
        }
        EXPECT_TRUE(is_net(pts)) << spp << " spp, pixel " << x << "," << y << ", dim " << dim;
        EXPECT_TRUE(is_stratified(line)) << spp << " spp, dim " << dim + 1;
      }
    }
  }
}

// spp not a power of 2: a pixel's first 2^m samples (any m) are still a net and every sample is
// distinct.
TEST(ZSobol, SampleCountsThatAreNotPowersOfTwo) {
  for (int spp : {3, 5, 12, 24, 100}) {
    const ZSobol z(16, 16, 3);
    for (int m = 0; (1 << m) <= spp; ++m) {
      std::vector<std::array<double, 2>> pts;
      for (int s = 0; s < (1 << m); ++s) pts.push_back(z.get2d(z.key(9, 4, uint64_t(s)), 4));
      EXPECT_TRUE(is_net(pts)) << spp << " spp, first " << (1 << m);
    }
    std::set<double> xs;
    for (int s = 0; s < spp; ++s) xs.insert(z.get1d(z.key(9, 4, uint64_t(s)), 4));
    EXPECT_EQ(xs.size(), size_t(spp));
  }
}

// Samples past a pixel's block of 2^kZSobolSampleBits come from fresh blocks: still nets, and no
// point repeats one of the first block.
TEST(ZSobol, SamplesBeyondTheBlockStartFreshBlocks) {
  const ZSobol z(8, 8, 1);
  std::set<double> xs;
  for (int block = 0; block < 3; ++block) {
    std::vector<std::array<double, 2>> pts;
    for (int s = 0; s < 16; ++s) {
      const uint64_t sample = (uint64_t(block) << kZSobolSampleBits) + uint64_t(s);
      pts.push_back(z.get2d(z.key(3, 3, sample), 6));
      xs.insert(pts.back()[0]);
    }
    EXPECT_TRUE(is_net(pts)) << "block " << block;
  }
  EXPECT_EQ(xs.size(), 48u);
}

TEST(ZSobol, NumbersAreInTheUnitIntervalAndDeterministic) {
  const ZSobol a(64, 48, 99), b(64, 48, 99), other_seed(64, 48, 100);
  int same_as_other_seed = 0;
  for (int y = 0; y < 48; y += 7)
    for (int x = 0; x < 64; x += 5)
      for (uint64_t s = 0; s < 20; ++s)
        for (uint32_t dim = 0; dim < 12; ++dim) {
          const double u = a.get1d(a.key(x, y, s), dim);
          EXPECT_GE(u, 0.0);
          EXPECT_LT(u, 1.0);
          // The same number however it is asked for, in any order, from any copy.
          EXPECT_EQ(u, b.get1d(b.key(x, y, s), dim));
          const auto p = a.get2d(a.key(x, y, s), dim);
          EXPECT_GE(std::min(p[0], p[1]), 0.0);
          EXPECT_LT(std::max(p[0], p[1]), 1.0);
          same_as_other_seed += u == other_seed.get1d(other_seed.key(x, y, s), dim);
        }
  EXPECT_EQ(same_as_other_seed, 0);
}

// Different dimensions of one pixel are decorrelated: over many pixels, the sample correlation
// of two dimensions' numbers is within 4 standard errors (1/√n) of 0, and the 2D points of
// dimension pairs (0, 2) and (2, 4) fill a 16×16 grid as uniform points would (chi-square).
TEST(ZSobol, DimensionsAreDecorrelated) {
  const int spp = 16, W = 32, H = 32;
  const ZSobol z(W, H, 5);
  for (auto [d1, d2] :
       {std::pair{0u, 2u}, std::pair{2u, 3u}, std::pair{4u, 9u}, std::pair{1u, 4u}}) {
    double sxy = 0, sx = 0, sy = 0, sxx = 0, syy = 0;
    std::vector<int> grid(256, 0);
    const double n = double(W) * H * spp;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x)
        for (int s = 0; s < spp; ++s) {
          const ZSobol::Key k = z.key(x, y, uint64_t(s));
          const double u = z.get1d(k, d1), v = z.get1d(k, d2);
          sx += u, sy += v, sxy += u * v, sxx += u * u, syy += v * v;
          ++grid[int(u * 16) * 16 + int(v * 16)];
        }
    const double cov = sxy / n - (sx / n) * (sy / n);
    const double corr = cov / std::sqrt((sxx / n - sx * sx / n / n) * (syy / n - sy * sy / n / n));
    EXPECT_LT(std::abs(corr), 4 / std::sqrt(n)) << d1 << "," << d2;
    double chi2 = 0;
    for (int c : grid) chi2 += (c - n / 256) * (c - n / 256) / (n / 256);
    EXPECT_LT(chi2, test::chi_square_critical(255, 1e-4)) << d1 << "," << d2;
  }
}

// Every number is uniform over the randomizations: over 4096 seeds, one sample's number in a
// dimension fills 64 bins as uniform numbers would.
TEST(ZSobol, EachNumberIsUniformOverSeeds) {
  for (uint32_t dim : {0u, 3u, 40u}) {
    std::vector<int> bins(64, 0);
    const int seeds = 4096;
    for (int seed = 0; seed < seeds; ++seed) {
      const ZSobol z(16, 16, uint64_t(seed));
      ++bins[int(z.get1d(z.key(5, 11, 3), dim) * 64)];
    }
    double chi2 = 0;
    const double e = seeds / 64.0;
    for (int c : bins) chi2 += (c - e) * (c - e) / e;
    EXPECT_LT(chi2, test::chi_square_critical(63, 1e-4)) << dim;
  }
}

}  // namespace zsobol_test
}  // namespace nimbus
