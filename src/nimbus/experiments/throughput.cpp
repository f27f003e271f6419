#include "nimbus/experiments/throughput.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "nimbus/experiments/infinite_walk.h"

namespace nimbus {
namespace {

const Rgb kSigmaS{{1.0, 5.0, 10.0}};
constexpr const char* kChannels[4] = {"r", "g", "b", "avg"};

// Records the weight at every edge, and nothing at scattering events.
struct EdgeRecorder {
  double* out;  // edges × 4 values: R, G, B and their average
  int edges;
  int recorded = 0;
  bool edge(const Rgb& w) {
    double* row = out + 4 * recorded;
    for (int i = 0; i < 3; ++i) row[i] = w[i];
    row[3] = w.average();
    return ++recorded < edges;
  }
  bool scatter(double, const Rgb&) { return true; }
};

// The q-quantile of sorted values, interpolated linearly between order statistics.
double quantile(const std::vector<double>& sorted, double q) {
  const double h = q * double(sorted.size() - 1);
  const size_t lo = size_t(std::floor(h));
  const size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (h - double(lo)) * (sorted[hi] - sorted[lo]);
}

}  // namespace

ExperimentReport run_throughput(const ExperimentOptions& options) {
  const int walks = options.quick ? 400 : 20000;
  const double spacing = options.quick ? 0.5 : 0.1, max_distance = options.quick ? 5 : 10;
  const int edges = int(std::lround(max_distance / spacing));
  struct Case {
    const char* name;
    ChromaticMedium medium;
  };
  const std::array<Case, 2> media = {
      Case{"homogeneous", homogeneous_medium(kSigmaS)},
      Case{"uncorrelated", uncorrelated_medium(kSigmaS, 0.9, 0.5, options.seed)}};
  const std::array<std::pair<const char*, EventRule>, 2> rules = {
      {{"max", EventRule::Max}, {"history", EventRule::History}}};

  std::string csv = "medium,rule,channel,distance,mean,std,q05,q25,q50,q75,q95,max,zero_fraction\n";
  std::string summary =
      fmt::format("throughput at distance {} over {} walks (mean / std):\n", max_distance, walks);
  std::vector<double> w(size_t(walks) * edges * 4);
  int case_index = 0;
  for (const Case& c : media)
    for (const auto& [rule_name, rule] : rules) {
      const EventPolicy policy{rule, 0, false};
      const uint64_t key = uint64_t(case_index++);
      std::fill(w.begin(), w.end(), 0.0);  // walks whose weights all reach 0 stop recording
      parallel_for_index(walks, options.threads, [&](int i) {
        Rng rng = Rng::for_sample(options.seed, key, uint64_t(i));
        TrackingCounters counters;
        EdgeRecorder recorder{&w[size_t(i) * edges * 4], edges};
        infinite_walk(c.medium, policy, 0.0, spacing, rng, counters, recorder);
      });
      std::vector<double> v(walks);
      for (int ch = 0; ch < 4; ++ch)
        for (int e = 0; e < edges; ++e) {
          double sum = 0, sum_sq = 0;
          int zeros = 0;
          for (int i = 0; i < walks; ++i) {
            v[i] = w[(size_t(i) * edges + e) * 4 + ch];
            sum += v[i];
            zeros += v[i] == 0;
          }
          const double mean = sum / walks;
          for (double x : v) sum_sq += (x - mean) * (x - mean);
          const double sd = std::sqrt(sum_sq / walks);
          std::sort(v.begin(), v.end());
          csv += fmt::format(
              "{},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n",
              c.name, rule_name, kChannels[ch], spacing * (e + 1), mean, sd, quantile(v, 0.05),
              quantile(v, 0.25), quantile(v, 0.5), quantile(v, 0.75), quantile(v, 0.95), v.back(),
              double(zeros) / walks);
          if (e == edges - 1)
            summary += fmt::format("  {:12} {:7} {:3}: {:.3f} / {:.3f}\n", c.name, rule_name,
                                   kChannels[ch], mean, sd);
        }
    }
  return {{write_text(options.out, "throughput.csv", csv)}, summary};
}

}  // namespace nimbus
