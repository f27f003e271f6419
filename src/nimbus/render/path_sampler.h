#pragma once
// The numbers of one pixel sample (integrator.sampler, docs/scene-format.md): from a ZSobol
// sequence (math/zsobol.h) or independent PCG numbers, and a PCG stream (math/rng.h) for what a
// path uses a variable number of times (the tracking estimators' tentative collisions, shadow
// rays' roulette, delta tracking's channel). The first number a free-flight or shadow ray
// estimator draws comes from the sampler too (`first_from`): the stream hands it out once.
//
// Dimensions are allocated the same way on every path, so a dimension serves one purpose at one
// depth (SampleDims). The independent sampler ignores them and draws from the path's stream in
// call order, which is the order nimbus drew its numbers in before it had a sampler: its images
// are those of earlier versions.

#include <array>
#include <cstdint>

#include "nimbus/math/rng.h"
#include "nimbus/math/zsobol.h"
#include "nimbus/render/scene.h"

namespace nimbus {

// Where a path's numbers come from in its sampler's dimensions.
struct SampleDims {
  static constexpr uint32_t kCamera = 0;      // 2D: position in the pixel
  static constexpr uint32_t kWavelength = 2;  // 1D: the path's wavelengths (spectral mode)
  static constexpr uint32_t kHero = 3;        // 1D: spectral MIS's hero channel
  static constexpr uint32_t kFirstBounce = 4;
  // Per bounce, from the bounce's first dimension:
  static constexpr uint32_t kDirection = 0;   // 2D: phase or diffuse direction
  static constexpr uint32_t kChoice = 2;      // 1D: phase lobe, or dielectric reflect / refract
  static constexpr uint32_t kRoulette = 3;    // 1D
  static constexpr uint32_t kFreeFlight = 4;  // 1D: the first number of the ray's tracking
  static constexpr uint32_t kLights = 5;      // per light (all are sampled), kPerLight each:
  static constexpr uint32_t kLightPoint = 0;  // 2D: the point on it
  static constexpr uint32_t kShadow = 2;      // 1D: the first number of its shadow ray's tracking
  static constexpr uint32_t kPerLight = 3;

  // Bounces from kBounces on draw from the path's stream: a sampler's number costs about ten
  // of the stream's, and stratification gains little that deep, while dense media make paths of
  // hundreds of bounces. Their dimensions are kStream and above.
  static constexpr int kBounces = 4;
  static constexpr uint32_t kStream = 0x80000000u;

  // The first dimension of bounce `depth` (0 at the camera ray's end) with `lights` lights.
  static constexpr uint32_t bounce(int depth, int lights) {
    return depth < kBounces
               ? kFirstBounce + uint32_t(depth) * (kLights + kPerLight * uint32_t(lights))
               : kStream;
  }
  static constexpr uint32_t light(uint32_t bounce, int i) {
    return bounce + kLights + kPerLight * uint32_t(i);
  }
};

class PathSampler {
 public:
  // `zsobol` is the render's sequence; unused by the independent sampler.
  PathSampler(const RenderSettings& settings, const ZSobol& zsobol, int x, int y, uint64_t pixel,
              uint64_t sample)
      : zsobol_(settings.sampler == RenderSettings::Sampler::ZSobol ? &zsobol : nullptr),
        key_(zsobol_ ? sequence_key(settings, zsobol, x, y, sample) : ZSobol::Key{}),
        rng_(Rng::for_sample(settings.seed, pixel, sample)) {}

  double get1d(uint32_t dim) {
    return zsobol_ && dim < SampleDims::kStream ? zsobol_->get1d(key_, dim) : rng_.uniform();
  }
  std::array<double, 2> get2d(uint32_t dim) {
    if (zsobol_ && dim < SampleDims::kStream) return zsobol_->get2d(key_, dim);
    const double u1 = rng_.uniform();
    return {u1, rng_.uniform()};
  }

  // Sample s's point. With a noise target, the even and the odd samples are two independent
  // randomizations of the sequence, s taking point ⌊s/2⌋ of randomization s mod 2: the means of
  // the two differ by the error of the pixel's mean, which render/noise_target.h estimates from
  // them (randomized quasi-Monte Carlo's replicates).
  static ZSobol::Key sequence_key(const RenderSettings& settings, const ZSobol& zsobol, int x,
                                  int y, uint64_t sample) {
    if (!(settings.noise_target > 0)) return zsobol.key(x, y, sample);
    ZSobol::Key k = zsobol.key(x, y, sample >> 1);
    if (sample & 1) k.seed = splitmix64(k.seed ^ 0x6a09e667f3bcc909ull);
    return k;
  }

  // The path's stream, for numbers used a variable number of times.
  Rng& rng() { return rng_; }
  // The stream's next number is dimension dim's (zsobol; independent: the stream's own), until
  // done() drops it if unused, so that a dimension serves one purpose only.
  void first_from(uint32_t dim) {
    if (zsobol_ && dim < SampleDims::kStream) rng_.set_next(get1d(dim));
  }
  void done() { rng_.clear_next(); }

 private:
  const ZSobol* zsobol_;
  ZSobol::Key key_;
  Rng rng_;
};

}  // namespace nimbus
