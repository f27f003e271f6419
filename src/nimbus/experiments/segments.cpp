#include "nimbus/experiments/segments.h"

#include <fmt/format.h>

#include <array>

#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace nimbus {
namespace {

struct Size {
  int width, height, spp;
};

RenderResult render_file(const std::filesystem::path& file, const Size& size, uint64_t seed,
                         const std::string& tracking, int threads) {
  const Scene scene = compile_scene(load_scene_file(
      file.string(),
      {fmt::format("film.width={}", size.width), fmt::format("film.height={}", size.height),
       fmt::format("integrator.spp={}", size.spp), fmt::format("integrator.seed={}", seed),
       "integrator.tracking=" + tracking,
       // Ratio-tracked shadow rays, as when docs/reproduction.md's figures were measured, and no
       // manifold sampling: Sec. 4 counts the segments of free paths, not of shadow rays.
       "integrator.transmittance=ratio", "integrator.manifold=false"}));
  RenderOptions options;
  options.threads = threads;
  return render(scene, options);
}

// Mean over pixels and channels of the squared difference of the pixel means.
double mse(const Film& a, const Film& reference) {
  double sum = 0;
  for (size_t p = 0; p < a.sum.size(); ++p) {
    const Rgb d = a.mean(int(p)) - reference.mean(int(p));
    sum += (d * d).sum();
  }
  return sum / (3.0 * double(a.sum.size()));
}

// The film's own estimate of the same quantity for an unbiased image: its mean variance.
double variance_estimate(const Film& f) {
  double sum = 0;
  for (size_t p = 0; p < f.sum.size(); ++p) sum += f.variance_of_mean(int(p)).sum();
  return sum / (3.0 * double(f.sum.size()));
}

}  // namespace

ExperimentReport run_segments(const ExperimentOptions& options) {
  const Size size = options.quick ? Size{24, 16, 2} : Size{96, 64, 16};
  const int reference_spp = options.quick ? 16 : 128;
  const std::array<const char*, 2> scenes = {"cloud", "translucent"};
  const std::array<const char*, 3> trackings = {"delta", "spectral-max", "spectral-history"};

  std::string csv =
      "scene,tracking,width,height,spp,seconds,segments_per_sample,lookups_per_sample,"
      "scatter_events_per_sample,segments_per_scatter_event,segments_relative_to_delta,"
      "lookups_relative_to_delta,segments_per_scatter_relative_to_delta,mse,"
      "reference_variance,variance_estimate,mse_x_seconds,efficiency_relative_to_delta\n";
  std::string summary = fmt::format("{}x{} at {} spp, reference {} spp:\n", size.width, size.height,
                                    size.spp, reference_spp);
  for (const char* name : scenes) {
    const std::filesystem::path file = options.scenes / (std::string(name) + ".json");
    const RenderResult reference = render_file(file, {size.width, size.height, reference_spp},
                                               options.seed + 1, "delta", options.threads);
    const double reference_variance = variance_estimate(reference.film);
    double delta_segments = 0, delta_lookups = 0, delta_step = 0, delta_cost = 0;
    for (const char* tracking : trackings) {
      const RenderResult r = render_file(file, size, options.seed, tracking, options.threads);
      const Counters& c = r.counters;
      const double samples = double(c.paths);
      const double segments = double(c.tracking.tentative_collisions) / samples;
      const double lookups = double(c.tracking.lookups) / samples;
      const double scatters = double(c.scatter_events) / samples, step = segments / scatters;
      // E[(image − reference)²] = Var(image) + Var(reference): both are unbiased and independent.
      const double error = mse(r.film, reference.film);
      const double cost = (error - reference_variance) * r.seconds;
      if (std::string(tracking) == "delta") {
        delta_segments = segments;
        delta_lookups = lookups;
        delta_step = step;
        delta_cost = cost;
      }
      csv += fmt::format(
          "{},{},{},{},{},{:.4f},{:.6g},{:.6g},{:.6g},{:.6g},{:.4f},{:.4f},{:.4f},{:.6g},{:.6g},"
          "{:.6g},{:.6g},{:.4f}\n",
          name, tracking, size.width, size.height, size.spp, r.seconds, segments, lookups, scatters,
          step, segments / delta_segments, lookups / delta_lookups, step / delta_step, error,
          reference_variance, variance_estimate(r.film), cost, delta_cost / cost);
      summary += fmt::format(
          "  {:11} {:16} segments/sample {:8.2f} ({:+.1f} % vs delta), scatter events/sample "
          "{:5.2f}, segments/scatter event {:6.2f} ({:+.1f} %), MSE x s {:.3g} (efficiency "
          "{:.2f}x delta)\n",
          name, tracking, segments, 100 * (segments / delta_segments - 1), scatters, step,
          100 * (step / delta_step - 1), cost, delta_cost / cost);
    }
  }
  return {{write_text(options.out, "segments.csv", csv)}, summary};
}

}  // namespace nimbus
