#pragma once
// PCG32 (O'Neill 2014) with one independent stream per (seed, pixel, sample index), so that an
// image does not depend on how pixels are spread over threads or processes.

#include <cstdint>

namespace nimbus {

constexpr uint64_t splitmix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

class Rng {
 public:
  constexpr Rng(uint64_t seed, uint64_t stream = 0)
      : state_(0), inc_((splitmix64(stream) << 1u) | 1u) {
    next_u32();
    state_ += splitmix64(seed);
    next_u32();
  }
  // The stream for one pixel sample: every key goes through the hash, so neighbours decorrelate.
  static constexpr Rng for_sample(uint64_t seed, uint64_t pixel, uint64_t sample) {
    return Rng(splitmix64(seed ^ splitmix64(pixel)), splitmix64(sample + 0x632be59bd9b4e019ull));
  }

  constexpr uint32_t next_u32() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    const uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    const uint32_t rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((-rot) & 31));
  }
  // Uniform in [0, 1), 53 random bits; or the number given to set_next, once.
  constexpr double uniform() {
    if (next_ >= 0) {
      const double u = next_;
      next_ = -1;
      return u;
    }
    const uint64_t hi = next_u32(), lo = next_u32();
    return static_cast<double>(((hi << 32) | lo) >> 11) * 0x1.0p-53;
  }
  // The next uniform() returns u in [0, 1) instead of the stream's number, which stays for the
  // call after: a sampler's number for the first of the numbers an estimator draws a variable
  // count of (render/path_sampler.h). clear_next drops it if unused.
  constexpr void set_next(double u) { next_ = u; }
  constexpr void clear_next() { next_ = -1; }

 private:
  uint64_t state_;
  uint64_t inc_;
  double next_ = -1;  // < 0: none
};

}  // namespace nimbus
