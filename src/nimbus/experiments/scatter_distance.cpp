#include "nimbus/experiments/scatter_distance.h"

#include <fmt/format.h>

#include <array>
#include <cmath>

#include "nimbus/experiments/infinite_walk.h"

namespace nimbus {
namespace {

const Rgb kSigmaS{{1.0, 5.0, 10.0}};
constexpr double kRange = 6;  // histogram over [0, kRange): exp(−6) of channel R lies beyond

struct Histograms {
  std::vector<double> first, between;  // counts per bin
  std::vector<Rgb> weighted;           // Σ w_k per bin
  Rgb weight_before{0.0};              // Σ w_{k−1}
  Rgb weighted_distance{0.0};          // Σ w_k t_k, for the weighted mean distance
  double distances = 0, distance_sum = 0;
  explicit Histograms(int bins) : first(bins), between(bins), weighted(bins, Rgb(0.0)) {}
  void add(const Histograms& o) {
    for (size_t b = 0; b < first.size(); ++b) {
      first[b] += o.first[b];
      between[b] += o.between[b];
      weighted[b] += o.weighted[b];
    }
    weight_before += o.weight_before;
    weighted_distance += o.weighted_distance;
    distances += o.distances;
    distance_sum += o.distance_sum;
  }
};

// Bins each distance between scattering events, for `events` events per walk.
struct ScatterRecorder {
  Histograms& h;
  double bin_width;
  int events;
  int k = 0;
  double last = 0;
  Rgb w_before{1.0};
  bool edge(const Rgb&) { return true; }
  bool scatter(double d, const Rgb& w) {
    const double t = d - last;
    const int b = int(t / bin_width);
    if (b < int(h.first.size())) {
      if (k == 0) h.first[b] += 1;
      h.between[b] += 1;
      h.weighted[b] += w;
    }
    h.weight_before += w_before;
    h.weighted_distance += w * t;
    h.distances += 1;
    h.distance_sum += t;
    last = d;
    w_before = w;
    return ++k < events;
  }
};

}  // namespace

ExperimentReport run_scatter_distance(const ExperimentOptions& options) {
  const int walks = options.quick ? 4000 : 200000, events = options.quick ? 8 : 16;
  const int bins = options.quick ? 30 : 300, blocks = 64;
  const double width = kRange / bins;
  const ChromaticMedium medium = homogeneous_medium(kSigmaS);
  const std::array<std::pair<const char*, EventRule>, 2> rules = {
      {{"max", EventRule::Max}, {"history", EventRule::History}}};

  std::string csv =
      "rule,distance_lo,distance_hi,sampled_first,sampled_between,weighted_r,weighted_g,"
      "weighted_b,analytic_r,analytic_g,analytic_b\n";
  std::string summary = fmt::format(
      "mean distance between scattering events ({} walks x {} events); closed form 1/sigma_s = "
      "{:.4f} {:.4f} {:.4f}\n",
      walks, events, 1 / kSigmaS[0], 1 / kSigmaS[1], 1 / kSigmaS[2]);
  uint64_t key = 0;
  for (const auto& [rule_name, rule] : rules) {
    const EventPolicy policy{rule, 0, false};
    std::vector<Histograms> per_block(blocks, Histograms(bins));
    parallel_for_index(blocks, options.threads, [&](int block) {
      for (int i = block; i < walks; i += blocks) {
        Rng rng = Rng::for_sample(options.seed, key, uint64_t(i));
        TrackingCounters counters;
        ScatterRecorder recorder{per_block[block], width, events};
        infinite_walk(medium, policy, 0.0, kNoEdges, rng, counters, recorder);
      }
    });
    ++key;
    Histograms h(bins);
    for (const Histograms& b : per_block) h.add(b);
    for (int b = 0; b < bins; ++b) {
      const double lo = b * width, hi = lo + width;
      Rgb weighted, analytic;
      for (int c = 0; c < 3; ++c) {
        weighted[c] = h.weighted[b][c] / (h.weight_before[c] * width);
        analytic[c] = (std::exp(-kSigmaS[c] * lo) - std::exp(-kSigmaS[c] * hi)) / width;
      }
      csv += fmt::format(
          "{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n", rule_name,
          lo, hi, h.first[b] / (walks * width), h.between[b] / (h.distances * width), weighted[0],
          weighted[1], weighted[2], analytic[0], analytic[1], analytic[2]);
    }
    summary += fmt::format(
        "  {:7} sampled {:.4f}, weighted per channel {:.4f} {:.4f} {:.4f}\n", rule_name,
        h.distance_sum / h.distances, h.weighted_distance[0] / h.weight_before[0],
        h.weighted_distance[1] / h.weight_before[1], h.weighted_distance[2] / h.weight_before[2]);
  }
  return {{write_text(options.out, "scatter_distance.csv", csv)}, summary};
}

}  // namespace nimbus
