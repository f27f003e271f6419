#include "nimbus/job/render_job.h"

#include <fmt/format.h>

#include <algorithm>
#include <memory>
#include <thread>

#include "nimbus/frep/tape.h"
#include "nimbus/job/fingerprint.h"
#include "nimbus/job/shared_render.h"
#include "nimbus/render/memory_estimate.h"
#include "nimbus/render/noise_target.h"
#include "nimbus/render/path_spectra.h"
#include "nimbus/render/renderer.h"
#include "nimbus/render/stats.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace nimbus {

RenderJob::RenderJob(RenderJobOptions options)
    : options_(std::move(options)),
      checkpoint_file_(!options_.checkpoint.empty() ? options_.checkpoint : options_.resume) {
  if (options_.spp < 0) throw std::invalid_argument("spp must be >= 0");
  if (!(options_.checkpoint_interval > 0))
    throw std::invalid_argument("the checkpoint interval must be > 0 seconds");
}

void RenderJob::prepare(const std::string& scene_file, const BuildMonitor& monitor) {
  load(scene_file, read_resume());
  check();
  if (!compile(monitor)) return;
  check_compiled();
}

int RenderJob::read_resume() {
  if (options_.resume.empty()) return options_.spp;
  try {
    resumed_ = load_checkpoint(options_.resume);
  } catch (const std::runtime_error& e) {
    throw JobError(fmt::format("--resume: {}", e.what()));
  }
  // Without an spp, a resumed render finishes what the checkpoint's render was asked for.
  return options_.spp > 0 ? options_.spp : resumed_->spp;
}

void RenderJob::load(const std::string& scene_file, int spp) {
  use_description(load_scene_file(scene_file, overrides()), spp);
  scene_file_ = scene_file;
}

void RenderJob::load_document(const nlohmann::json& document, const std::string& source, int spp) {
  use_description(load_scene_json(document, source, overrides()), spp);
  scene_file_.clear();
}

std::vector<std::string> RenderJob::overrides() const {
  // The seed is part of what the render is of (the document, hence the fingerprint); spp only
  // says how many samples to take, and goes to the settings as it is.
  std::vector<std::string> overrides = options_.overrides;
  if (options_.seed) overrides.push_back(fmt::format("integrator.seed={}", *options_.seed));
  return overrides;
}

void RenderJob::use_description(SceneDesc desc, int spp) {
  desc_ = std::move(desc);
  if (spp > 0) desc_.settings.spp = spp;
  compiled_ = false;
}

void RenderJob::set_scene(Scene scene, const nlohmann::json& identity) {
  if (!options_.overrides.empty() || options_.seed)
    throw std::invalid_argument(
        "a scene built in code takes no overrides and no seed: set them in its settings");
  const int spp = read_resume();
  scene_ = std::move(scene);
  if (spp > 0) scene_.settings.spp = spp;
  nlohmann::json of{{"scene", identity},
                    {"seed", scene_.settings.seed},
                    {"max_depth", scene_.settings.max_depth}};
  // Where blocks stop (render/noise_target.h); absent without one, as before it existed.
  if (scene_.settings.noise_target > 0) {
    of["noise_target"] = scene_.settings.noise_target;
    of["noise_min_spp"] = scene_.settings.noise_min_spp;
  }
  fingerprint_ = render_fingerprint(of);
  compiled_ = true;
  check();
  check_compiled();
}

void RenderJob::check() const {
  const int width = compiled_ ? scene_.settings.width : desc_.settings.width;
  const int height = compiled_ ? scene_.settings.height : desc_.settings.height;
  const int spp = compiled_ ? scene_.settings.spp : desc_.settings.spp;
  const AovSet aovs = film_aovs(compiled_ ? scene_.settings : desc_.settings);
  if (resumed_) {
    const std::string& file = options_.resume;
    // The document and the settings now; the files it reads once they are read (check_compiled).
    const auto without_files = [](nlohmann::json j) {
      if (j.is_object()) j.erase("files");
      return j;
    };
    const nlohmann::json now = compiled_ ? fingerprint_ : render_fingerprint(desc_, {});
    if (const std::string d =
            fingerprint_difference(without_files(resumed_->fingerprint), without_files(now));
        !d.empty())
      throw JobError(fmt::format(
          "--resume {}: the checkpoint is of another scene or other settings ({})", file, d));
    if (resumed_->film.width != width || resumed_->film.height != height)
      throw JobError(fmt::format("--resume {}: a film of {}x{} pixels, the scene's image is {}x{}",
                                 file, resumed_->film.width, resumed_->film.height, width, height));
    // The document holds film.aov, but a scene built in code stands for it by its identity.
    if (resumed_->film.aov.layers != aovs.recorded())
      throw JobError(fmt::format(
          "--resume {}: the checkpoint's film holds the sums of other AOVs than this render's",
          file));
    const uint32_t most = resumed_->film.most_samples();
    if (most > uint32_t(spp))
      throw JobError(
          fmt::format("--resume {}: pixels of the checkpoint hold {} samples, more than --spp {}",
                      file, most, spp));
  }
  // A scene built in code holds its octrees already: only a description's render is estimated.
  if (!compiled_) check_render_memory(desc_, options_.threads, options_.max_memory);
}

bool RenderJob::compile(const BuildMonitor& monitor) {
  scene_ = compile_scene(desc_, monitor, &inputs_);
  // A copy of the whole document (issue 26: 1.7 KB an object), for checkpoints only.
  if (!checkpoint_file_.empty()) fingerprint_ = render_fingerprint(desc_, inputs_);
  compiled_ = !(monitor.cancel && monitor.cancel());
  return compiled_;
}

void RenderJob::check_compiled() const {
  if (!resumed_) return;
  const std::string& file = options_.resume;
  if (const std::string d = fingerprint_difference(resumed_->fingerprint, fingerprint_); !d.empty())
    throw JobError(fmt::format(
        "--resume {}: the checkpoint is of another scene or other settings ({})", file, d));
  if (resumed_->majorants != majorant_hash(scene_))
    throw JobError(fmt::format(
        "--resume {}: the checkpoint's majorant octrees differ from this render's (another "
        "nimbus build?)",
        file));
  if (resumed_->film.exponent != scene_.film_exponent)
    throw JobError(fmt::format(
        "--resume {}: the checkpoint's film sums in units of 2^{}, this render's in 2^{} (another "
        "nimbus build?)",
        file, resumed_->film.exponent - kExactSumFractionBits,
        scene_.film_exponent - kExactSumFractionBits));
  if (resumed_->film.aov.layers.has(Aov::Depth) &&
      resumed_->film.aov.depth_exponent != depth_exponent(scene_))
    throw JobError(fmt::format(
        "--resume {}: the checkpoint's film sums depths in units of 2^{}, this render's in 2^{} "
        "(another nimbus build?)",
        file, resumed_->film.aov.depth_exponent - kExactSumFractionBits,
        depth_exponent(scene_) - kExactSumFractionBits));
}

JobOutcome RenderJob::run(JobChannel* channel) {
  if (!compiled_) throw std::logic_error("RenderJob::run before the scene was compiled");
  // One call of the renderer, over tiles, unless units must be shared or checkpointed; shown
  // alone, the render goes in passes of samples.
  if (!channel && checkpoint_file_.empty())
    return options_.display || noise_rule(scene_.settings).on() ? run_in_passes() : run_at_once();
  return run_shared(channel);
}

JobOutcome RenderJob::run_at_once() {
  RenderOptions render_options;
  render_options.threads = options_.threads;
  render_options.cancel = options_.cancel;
  render_options.progress = options_.progress;
  RenderResult r = render(scene_, render_options);
  JobOutcome outcome;
  outcome.stopped = r.cancelled || (options_.cancel && options_.cancel());
  outcome.film = std::move(r.film);
  outcome.counters = r.counters;
  outcome.seconds = r.seconds;
  outcome.threads = r.threads;
  return outcome;
}

JobOutcome RenderJob::run_in_passes() {
  // A pass is one call of the renderer over tiles, so only its last tiles leave threads idle
  // (work units of 0.5 s left one of two threads idle at the end of each: 4 %, passes 2.5 %;
  // issue 28). Passes grow until one lasts half a second, the display's interval; the film after
  // each is the image so far, and at the end the bits of one call, since the exact sums do not
  // depend on the split.
  // With a noise target, blocks that are done take no more samples (render/noise_target.h), the
  // render ends once all are, and the progress is the share of the samples predicted from the
  // blocks' errors.
  constexpr double kDisplayInterval = 0.5;
  const int spp = scene_.settings.spp;
  const NoiseRule rule = noise_rule(scene_.settings);
  JobOutcome outcome;
  outcome.film = make_film(scene_);
  int done = 0, pass = 1;
  NoiseProgress noise;
  while (done < spp) {
    RenderOptions o;
    o.threads = options_.threads;
    o.cancel = options_.cancel;
    o.range.s0 = done;
    o.range.s1 = std::min(spp, done + pass);
    if (options_.progress && !rule.on())
      o.progress = [&, s0 = done, n = o.range.s1 - done](double f) {
        options_.progress((s0 + f * n) / spp);
      };
    const RenderStats r = render_into(scene_, outcome.film, o);
    outcome.counters += r.counters;
    outcome.seconds += r.seconds;
    outcome.threads = r.threads;
    if (r.cancelled || (options_.cancel && options_.cancel())) {
      outcome.stopped = true;
      break;
    }
    done = o.range.s1;
    pass = std::clamp(int(pass * kDisplayInterval / std::max(r.seconds, 1e-3)), 1, 2 * pass);
    if (rule.on()) {
      noise = noise_progress(rule, outcome.film);
      if (options_.noise_progress) options_.noise_progress(noise);
      if (options_.progress) options_.progress(noise.converged < 1 ? noise.fraction : 1.0);
      if (noise.converged >= 1) break;
    }
    if (done < spp && options_.display) options_.display(outcome.film);
  }
  return outcome;
}

JobOutcome RenderJob::run_shared(JobChannel* channel) {
  SharedRenderSettings s;
  s.spp = scene_.settings.spp;
  s.threads = options_.threads;
  s.start = resumed_ ? resumed_->film : make_film(scene_);
  s.display = options_.display;
  const uint64_t held_at_start = samples_held(s.start);
  // Why the last checkpoint could not be saved; empty: it was, or none was due.
  auto failure = std::make_shared<std::string>();
  if (!checkpoint_file_.empty()) {
    Checkpoint header;
    header.fingerprint = fingerprint_;
    header.majorants = majorant_hash(scene_);
    header.spp = scene_.settings.spp;
    s.checkpoint_interval = options_.checkpoint_interval;
    // Units are short next to the interval, so checkpoints come on time.
    s.unit_seconds = std::min(s.unit_seconds, s.checkpoint_interval / 4);
    s.checkpoint = [header, path = checkpoint_file_, held_at_start, failure,
                    warn = options_.warning](const Film& film) mutable {
      // Nothing rendered yet: the file would gain nothing, and a fresh render's checkpoint
      // would replace an earlier one with an empty film.
      if (samples_held(film) == held_at_start) return;
      header.film = film;
      try {
        save_checkpoint(header, path);
        failure->clear();
      } catch (const std::exception& e) {
        *failure = e.what();
        if (warn) warn(fmt::format("--checkpoint: {} (not saved)", e.what()));
      }
    };
  }
  s.progress = options_.progress;
  s.noise_progress = options_.noise_progress;
  s.stop = options_.cancel;
  SharedRenderResult r = lead_shared_render(scene_, channel, std::move(s));
  JobOutcome outcome;
  outcome.film = std::move(r.film);
  outcome.counters = r.counters;
  outcome.seconds = r.seconds;
  outcome.threads =
      options_.threads > 0 ? options_.threads : int(std::thread::hardware_concurrency());
  outcome.processes = channel ? channel->size() : 1;
  if (channel) outcome.samples_per_rank = std::move(r.samples_per_rank);
  outcome.samples_at_start = held_at_start;
  outcome.stopped = r.stopped;
  outcome.checkpoint_failure = *failure;
  return outcome;
}

void RenderJob::work(JobChannel& channel) {
  if (!compiled_) throw std::logic_error("RenderJob::work before the scene was compiled");
  work_on_shared_render(scene_, channel, options_.threads, options_.cancel);
}

nlohmann::json RenderJob::stats(const JobOutcome& outcome) const {
  RenderResult result;
  result.film = outcome.film;
  result.counters = outcome.counters;
  result.seconds = outcome.seconds;
  result.threads = outcome.threads;
  // This run's samples: a resumed film holds the checkpoint's too, which took none of its time.
  nlohmann::json j = render_stats(scene_, result, scene_file_,
                                  samples_held(outcome.film) - outcome.samples_at_start);
  if (!outcome.samples_per_rank.empty())
    j["mpi"] = {{"ranks", outcome.processes}, {"samples_per_rank", outcome.samples_per_rank}};
  if (!checkpoint_file_.empty())
    j["checkpoint"] = {{"file", checkpoint_file_},
                       {"samples_at_start", outcome.samples_at_start},
                       {"samples", samples_held(outcome.film)}};
  return j;
}

std::string RenderJob::summary(const JobOutcome& outcome) const {
  const RenderSettings& s = scene_.settings;
  const double samples = double(samples_held(outcome.film) - outcome.samples_at_start);
  std::string where = fmt::format("{} threads", outcome.threads);
  if (outcome.processes > 1) where += fmt::format(" x {} processes", outcome.processes);
  std::string spp = fmt::format("{} spp", s.spp);
  if (const NoiseRule rule = noise_rule(s); rule.on()) {
    const NoiseProgress p = noise_progress(rule, outcome.film);
    spp = fmt::format(
        "noise target {:g}: {:.1f} spp on average, {} at most (cap {}), {:.1f} % of pixels at "
        "the target",
        rule.target, double(samples_held(outcome.film)) / outcome.film.pixels(),
        outcome.film.most_samples(), s.spp, 100 * (p.converged - p.capped));
  }
  return fmt::format("{}x{}, {} in {:.2f} s ({:.3g} samples/s, {})", s.width, s.height, spp,
                     outcome.seconds, outcome.seconds > 0 ? samples / outcome.seconds : 0.0, where);
}

std::vector<NamedFile> RenderJob::files_read() const {
  std::vector<NamedFile> read = scene_inputs(scene_file_, inputs_);
  if (!options_.resume.empty() && !options_.checkpoint.empty() &&
      !same_file(options_.resume, options_.checkpoint))
    read.push_back({"the checkpoint of --resume", options_.resume});
  return read;
}

std::vector<NamedFile> RenderJob::files_written() const {
  if (!options_.checkpoint.empty()) return {{"--checkpoint", options_.checkpoint}};
  if (!options_.resume.empty()) return {{"--resume (its later checkpoints)", options_.resume}};
  return {};
}

double object_memory(const SceneDesc& desc) {
  double bytes = 0;
  for (const ObjectDesc& o : desc.objects)
    bytes += object_memory(o.copies(), count_quadrics(*o.shape));
  return bytes;
}

void check_render_memory(const SceneDesc& desc, int threads, std::optional<uint64_t> max_memory) {
  // One per solid holding a medium, and the field's if an index-matched object holds one
  // (render/scene.h); none for a scene without media (issue 29: 42 MiB were charged for it). A
  // solid of constant density is homogeneous: its octree is one node, never split (media/
  // octree.h), and is not charged the node budget (issue 26: 1 024 dielectric spheres of one
  // homogeneous medium were refused as needing 42 GiB).
  std::size_t octrees = 0;
  std::size_t field_objects = 0;
  for (const ObjectDesc& o : desc.objects) {
    const int medium = compiled_medium(o);
    if (has_own_octree(medium, o.surface.type))
      octrees += o.copies() * !desc.media[size_t(medium)].constant_density;
    if (medium >= 0 && !has_own_octree(medium, o.surface.type)) field_objects += o.copies();
  }
  octrees += field_objects > 0;
  const int bins =
      desc.settings.spectral.mode == SpectralSettings::Mode::Spectral ? kSpectralBins : 3;
  const int workers = threads > 0 ? threads : int(std::thread::hardware_concurrency());
  MemoryEstimate need =
      estimate_render_memory(desc.settings.width, desc.settings.height, octrees, bins, workers,
                             field_objects, film_aovs(desc.settings));
  need.objects = object_memory(desc);
  const uint64_t limit = max_memory ? *max_memory : available_memory();
  if (limit > 0 && need.total() > double(limit))
    throw JobError(fmt::format(
        "the render needs about {} (film {}, image {}, majorant octrees {}{}{}), more than the "
        "{} {}",
        format_memory(need.total()), format_memory(need.film), format_memory(need.image),
        format_memory(need.octrees),
        need.media_lists > 0 ? ", media lists " + format_memory(need.media_lists) : "",
        // Only where they count: most scenes' objects take kilobytes.
        need.objects >= (1 << 20) ? ", objects " + format_memory(need.objects) : "",
        format_memory(double(limit)), max_memory ? "allowed by --max-memory" : "available"));
}

}  // namespace nimbus
