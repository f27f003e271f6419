#include "nimbus/view/view_session.h"

#include <fmt/format.h>
#include <sys/stat.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "nimbus/io/film_image.h"
#include "nimbus/job/render_job.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "nimbus/spectral/color.h"
#include "nimbus/view/preview.h"

namespace nimbus {
namespace {

bool same_camera(const CameraDesc& a, const CameraDesc& b) {
  return a.type == b.type && a.from == b.from && a.to == b.to && a.up == b.up && a.fov == b.fov &&
         a.width == b.width;
}

// A pass aims at this long: short enough to follow a camera move at once, long enough that the
// image is not copied out more often than a page can show it.
constexpr double kPassSeconds = 0.3;

}  // namespace

double view_noise(const Film& film) {
  const auto luminance = [](const Rgb& c) { return linear_srgb_to_xyz(c).y; };
  double var = 0, mean = 0;
  for (int p = 0; p < film.pixels(); ++p) {
    if (film.samples[size_t(p)] < 2) return 0;
    var += std::abs(luminance(film.variance_of_mean(p)));
    mean += luminance(film.mean(p));
  }
  return mean > 0 ? std::sqrt(var / film.pixels()) / (mean / film.pixels()) : 0;
}

ViewSession::ViewSession(ViewOptions options) : options_(std::move(options)) {
  if (!load()) throw SceneError(frame_.error);
  if (options_.mesh_error > 0) mesh_thread_ = std::thread([this] { mesh_loop(); });
  thread_ = std::thread([this] { loop(); });
}

ViewSession::~ViewSession() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  interrupt_ = true;
  wake_.notify_all();
  mesh_wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (mesh_thread_.joinable()) mesh_thread_.join();
}

ViewFrame ViewSession::frame() const {
  std::lock_guard lock(mutex_);
  return frame_;
}

void ViewSession::set_camera(const CameraDesc& camera) {
  {
    std::lock_guard lock(mutex_);
    pending_camera_ = camera;
    interrupt_ = true;
  }
  wake_.notify_all();
}

bool ViewSession::wait(const std::function<bool(const ViewFrame&)>& until,
                       double timeout_seconds) const {
  std::unique_lock lock(mutex_);
  return changed_.wait_for(lock, std::chrono::duration<double>(timeout_seconds),
                           [&] { return until(frame_); });
}

ViewSession::Stamp ViewSession::stamp(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return {path};
  return {path,
          int(st.st_mode & S_IFMT),
          uint64_t(st.st_dev),
          uint64_t(st.st_ino),
          int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec,
          int64_t(st.st_size)};
}

bool ViewSession::files_changed() const {
  return std::any_of(watched_.begin(), watched_.end(),
                     [](const Stamp& s) { return stamp(s.path) != s; });
}

bool ViewSession::load() {
  // The scene file is stamped before it is read, so that an edit made while it loads is seen next
  // time; the files it names are stamped once they are known, after reading. A load that fails
  // keeps watching the files of the last good one.
  std::vector<Stamp> watched{stamp(options_.scene)};
  for (size_t i = 1; i < watched_.size(); ++i) watched.push_back(stamp(watched_[i].path));
  try {
    std::vector<std::string> overrides = options_.overrides;
    if (options_.seed) overrides.push_back("integrator.seed=" + std::to_string(*options_.seed));
    if (options_.noise_target)
      overrides.push_back(fmt::format("integrator.noise_target={}", *options_.noise_target));
    SceneDesc desc = load_scene_file(options_.scene, overrides);
    if (options_.spp > 0) desc.settings.spp = options_.spp;
    check_render_memory(desc, options_.threads, options_.max_memory);
    std::vector<InputFile> inputs;
    watched.resize(1);
    for (const InputFile& f : desc.inputs) watched.push_back(stamp(f.path));
    BuildMonitor monitor;
    monitor.cancel = [this] {
      std::lock_guard lock(mutex_);
      return stop_;
    };
    auto scene = std::make_unique<Scene>(compile_scene(desc, monitor, &inputs));
    for (const InputFile& f : inputs) watched.push_back(stamp(f.path));
    watched_ = std::move(watched);
    if (monitor.cancel()) return false;
    // The page's camera stays unless the file's camera, or the film's size, changed.
    const bool resized = !scene_ || scene_->settings.width != scene->settings.width ||
                         scene_->settings.height != scene->settings.height;
    if (!scene_ || resized || !same_camera(desc.camera, file_camera_)) camera_ = desc.camera;
    file_camera_ = desc.camera;
    scene->camera = compile_camera(camera_, scene->settings);
    scene_ = std::move(scene);
    std::optional<PreviewScene> meshes;
    if (options_.mesh_error > 0) meshes = preview_scene(*scene_);
    // The frame's film is the new scene's before the load counts: a caller that waits for the
    // load (or is woken by the mesher) never sees the old film under the new count.
    restart(Clock::now());
    std::lock_guard lock(mutex_);
    frame_.error.clear();
    ++frame_.loads;
    if (meshes) {
      pending_meshes_ = std::move(meshes);
      mesh_wake_.notify_all();
    }
  } catch (const std::exception& e) {
    watched_ = std::move(watched);
    std::lock_guard lock(mutex_);
    frame_.error = printable_line(e.what());
    ++frame_.version;  // the page learns of the error as of an image
    changed_.notify_all();
    return false;
  }
  return true;
}

void ViewSession::restart(Clock::time_point now) {
  film_ = make_film(*scene_);
  spp_ = 0;
  pass_spp_ = 1;
  samples_ = 0;
  render_seconds_ = 0;
  restarted_ = now;
  need_preview_ = true;
  std::lock_guard lock(mutex_);
  frame_.film_image.reset();
  frame_.width = film_.width;
  frame_.height = film_.height;
  frame_.spp = 0;
  frame_.target_spp = scene_->settings.spp;
  frame_.samples_per_second = 0;
  frame_.noise = 0;
  frame_.pixels_done = noise_rule(scene_->settings).on() ? 0 : -1;
  frame_.camera = camera_;
  ++frame_.restarts;
}

void ViewSession::publish(std::shared_ptr<const Image> image, bool preview) {
  const double elapsed = std::chrono::duration<double>(Clock::now() - restarted_).count();
  const double noise = preview ? 0 : view_noise(film_);
  const NoiseRule rule = noise_rule(scene_->settings);
  const double pixels_done = rule.on() ? noise_progress(rule, film_).converged : -1;
  std::lock_guard lock(mutex_);
  frame_.pixels_done = pixels_done;
  ++frame_.version;
  frame_.image = std::move(image);
  frame_.preview = preview;
  if (!preview) frame_.film_image = frame_.image;
  frame_.spp = spp_;
  frame_.elapsed = elapsed;
  frame_.samples_per_second = render_seconds_ > 0 ? double(samples_) / render_seconds_ : 0;
  frame_.noise = noise;
  changed_.notify_all();
}

void ViewSession::render_preview_frame() {
  PreviewOptions po;
  po.downscale = preview_downscale(film_.width, film_.height, options_.preview_pixels);
  tbb::task_arena arena(options_.threads > 0 ? options_.threads : tbb::task_arena::automatic);
  auto image = std::make_shared<Image>(arena.execute([&] { return render_preview(*scene_, po); }));
  need_preview_ = false;
  publish(std::move(image), true);
}

void ViewSession::render_pass() {
  RenderOptions ro;
  ro.threads = options_.threads;
  ro.range.s0 = spp_;
  ro.range.s1 = std::min(scene_->settings.spp, spp_ + pass_spp_);
  ro.cancel = [this] { return interrupt_.load(std::memory_order_relaxed); };
  const auto held = [&] {
    return std::accumulate(film_.samples.begin(), film_.samples.end(), uint64_t(0));
  };
  const uint64_t before = held();
  const RenderStats stats = render_into(*scene_, film_, ro);
  // A cancelled pass leaves pixels at two sample counts: start again.
  if (stats.cancelled) return restart(Clock::now());
  spp_ = ro.range.s1;
  // With a noise target, blocks that are done took none of the pass's samples, and once all
  // are the film is finished: refining stops (render/noise_target.h).
  samples_ += held() - before;
  if (const NoiseRule rule = noise_rule(scene_->settings);
      rule.on() && noise_progress(rule, film_).converged >= 1)
    spp_ = scene_->settings.spp;
  render_seconds_ += stats.seconds;
  pass_spp_ =
      std::clamp(int(pass_spp_ * kPassSeconds / std::max(stats.seconds, 1e-3)), 1, 2 * pass_spp_);
  // With the scene's AOVs (film.aov), as `nimbus render` writes them: the saved EXR has them.
  publish(std::make_shared<Image>(to_image(film_, scene_->settings.aovs)), false);
}

void ViewSession::mesh_loop() {
  PreviewMeshOptions mo;
  mo.relative_error = options_.mesh_error;
  PreviewMesher mesher(mo);
  // As many threads as the render: the meshes make the page responsive, which matters more than
  // the path tracer's first seconds, and meshing is over in seconds.
  tbb::task_arena arena(options_.threads > 0 ? options_.threads : tbb::task_arena::automatic);
  for (;;) {
    PreviewScene scene;
    {
      std::unique_lock lock(mutex_);
      mesh_wake_.wait(lock, [&] { return stop_ || pending_meshes_.has_value(); });
      if (stop_) return;
      scene = std::move(*pending_meshes_);
      pending_meshes_.reset();
    }
    const auto start = Clock::now();
    PreviewMeshStats stats;
    auto meshes = std::make_shared<const std::string>(
        arena.execute([&] { return mesher.update(scene, &stats); }));
    std::lock_guard lock(mutex_);
    frame_.meshes = std::move(meshes);
    ++frame_.mesh_version;
    frame_.mesh_stats = stats;
    frame_.mesh_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    changed_.notify_all();
  }
}

void ViewSession::loop() {
  auto next_watch = Clock::now();
  for (;;) {
    std::optional<CameraDesc> camera;
    {
      std::lock_guard lock(mutex_);
      if (stop_) return;
      camera.swap(pending_camera_);
      interrupt_ = false;
    }
    const auto now = Clock::now();
    if (now >= next_watch) {
      next_watch = now + std::chrono::duration_cast<Clock::duration>(
                             std::chrono::duration<double>(options_.watch_interval));
      if (files_changed()) load();
    }
    if (camera) {
      camera_ = *camera;
      scene_->camera = compile_camera(camera_, scene_->settings);
      moved_ = now;
      restart(now);
    }
    if (need_preview_) {
      render_preview_frame();
      continue;
    }
    const auto rested = moved_ + std::chrono::duration_cast<Clock::duration>(
                                     std::chrono::duration<double>(options_.rest));
    if (now >= rested && spp_ < scene_->settings.spp) {
      render_pass();
      continue;
    }
    std::unique_lock lock(mutex_);
    wake_.wait_until(lock, now < rested ? std::min(rested, next_watch) : next_watch,
                     [&] { return stop_ || pending_camera_.has_value(); });
  }
}

}  // namespace nimbus
