#pragma once
// Rendering to a noise target (integrator.noise_target, `--noise-target E`): each 8 × 8 block of
// pixels takes samples until its estimated relative error is at most E, or until it holds the
// scene's spp, the cap (docs/noise-target.md).
//
// Passes. A block is decided only at the pass ends n_0 = min_spp (rounded up to even),
// n_{k+1} = n_k + max(n_0, 2⌊n_k / 8⌋) (about 1.25× more each), and at the cap, from its own
// pixels' sums and nothing else. Those sums are exact (render/exact_sum.h), so a block stops at
// the same count, with the same bits, however its samples were split between threads, calls,
// work units, processes and resumed checkpoints: the image stays deterministic.
//
// The error. The even and the odd samples of a pixel are two independent estimates of its
// mean: two randomizations of the sampler's sequence (PathSampler::sequence_key; independent
// numbers with the independent sampler). The film sums the odd ones again in its Half layer.
// With n (even) samples, the two halves' means a and b differ by d = a − b, and E[d²] is twice
// the variance of either, four times that of the pixel's mean (a + b)/2: d²/4 estimates the
// error of the mean, the quasi-Monte Carlo gain of each randomization included (a sample
// variance would miss it, and overstate the error of smooth pixels), and from exact sums (the
// film's sums of squares are doubles, whose rounding depends on how the samples were split).
// A pixel's relative error in channel c is √(d_c²/4) / max(|m_c|, 2⁻⁸), m_c its mean (below
// 2⁻⁸ of display white the error counts as absolute); a block's error is the root mean square of
// its pixels' over the three channels.
//
// Bias. The decision reads d, which is uncorrelated with the pixel's mean a + b, and normalises it
// by the means of the block's 64 pixels: a block that stops early is not brighter or darker than
// one that runs long beyond a second-order term (tests/noise_target_test.cpp measures it). The
// rule is consistent: as E goes to 0 every block runs to the cap.

#include <cstdint>

#include "nimbus/render/film.h"

namespace nimbus {

struct RenderSettings;

inline constexpr int kNoiseBlock = 8;          // pixels on a side of a decided block
inline constexpr double kNoiseFloor = 0x1p-8;  // below it a channel's error counts as absolute

// The settings of the rule: integrator.noise_target, integrator.noise_min_spp and the spp cap.
struct NoiseRule {
  double target = 0;  // 0: off, every pixel takes `cap` samples
  int min_spp = 16;
  int cap = 0;
  bool on() const { return target > 0; }
};
NoiseRule noise_rule(const RenderSettings& settings);

// The first pass end after n samples (n < cap): where a block is next decided.
int next_pass_end(const NoiseRule& rule, int n);
// Whether n samples is a pass end (or the cap).
bool is_pass_end(const NoiseRule& rule, int n);

// Whether sample s of a pixel goes into the film's Half sum: the odd ones, one randomization.
inline bool in_half(uint64_t s) {
  return (s & 1) != 0;
}

// The pixels [x0, x1) × [y0, y1) of block (bx, by) of a film, cut at its edges.
struct NoiseBlock {
  int x0, y0, x1, y1;
};
NoiseBlock noise_block(const Film& film, int bx, int by);
inline int noise_blocks_across(int width) {
  return (width + kNoiseBlock - 1) / kNoiseBlock;
}

// The block's estimated relative error (above) at its pixels' common count, which must be even
// and at least 2; the film must hold the Half layer.
double block_error(const Film& film, const NoiseBlock& block);
// Whether the block takes no more samples: it holds the cap, or a pass end at which its error
// is at most the target. Its pixels must hold one count.
bool block_done(const NoiseRule& rule, const Film& film, const NoiseBlock& block);

// How far a render to a noise target has come, from the film's blocks: the share of pixels that
// are done, of those that reached the cap above the target, and of the samples it is predicted
// to take that it holds, each block not done predicted to need n (e / E)² samples (the error
// falls as 1/√n), at most the cap.
struct NoiseProgress {
  double converged = 0;  // done: at the target, or at the cap
  double capped = 0;     // at the cap with an error above the target
  double fraction = 0;
};
NoiseProgress noise_progress(const NoiseRule& rule, const Film& film);

}  // namespace nimbus
