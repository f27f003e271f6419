#pragma once
// What `nimbus view` renders: a scene file watched and rendered progressively on a thread of its
// own, for the web page (view/view_server.h) to show. A camera move restarts the render with a
// quick preview (render/preview.h) while the camera moves and the path tracer once it rests; a
// saved scene file (or a file it reads) is loaded again, and one that fails to load leaves its
// one-line error beside the last good image. The film a session refines is `render_into`'s, so
// at its spp it holds the bits `nimbus render` writes for the same scene, camera and seed.
//
//   ViewSession session(options);      // loads and compiles: SceneError or JobError, as render
//   session.set_camera(camera);        // from the page
//   ViewFrame f = session.frame();     // the image now, its spp, samples/s, noise, error

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "nimbus/io/image.h"
#include "nimbus/render/film.h"
#include "nimbus/render/scene.h"
#include "nimbus/scene/scene_desc.h"
#include "nimbus/view/preview_mesh.h"

namespace nimbus {

struct ViewOptions {
  std::string scene;                   // the scene file
  std::vector<std::string> overrides;  // --set KEY=VALUE, in order
  int spp = 0;                         // > 0: refine to this many samples; 0: the scene's spp
  std::optional<double> noise_target;  // overrides integrator.noise_target
  std::optional<uint64_t> seed;        // overrides integrator.seed
  int threads = 0;                     // 0: all cores
  std::optional<uint64_t> max_memory;  // bytes; none: the memory the system has available
  double watch_interval = 0.25;        // seconds between looks at the scene's files
  double rest = 0.2;                   // seconds the camera rests before the path tracer starts
  int preview_pixels = 1 << 16;        // a preview's pixel budget (preview_downscale)
  // The page's meshes (view/preview_mesh.h): their error as a fraction of each object's size;
  // 0: none.
  double mesh_error = 1.0 / 256;
};

// What the page shows, as of one moment.
struct ViewFrame {
  uint64_t version = 0;                     // changes with every new image
  std::shared_ptr<const Image> image;       // linear RGB; null before the first
  bool preview = false;                     // the image is the preview, not the film
  std::shared_ptr<const Image> film_image;  // the film's pixel means (as render writes them);
                                            // null until the path tracer's first pass
  int width = 0, height = 0;                // the film's size
  int spp = 0, target_spp = 0;              // samples per pixel in the film, and to reach
  double samples_per_second = 0;            // pixel samples, since the last restart
  double elapsed = 0;                       // seconds since the last restart
  double noise = 0;                         // view_noise of the film
  // With a noise target (render/noise_target.h): the share of pixels done; -1 without one.
  double pixels_done = -1;
  std::string error;      // why the scene file last failed to load; "" if it loaded
  uint64_t loads = 0;     // successful loads of the scene file
  uint64_t restarts = 0;  // camera moves and loads that restarted the render
  CameraDesc camera;      // the view rendered
  // The objects' meshes for the page (view/preview_mesh.h), null until the first scene is
  // meshed; mesh_version counts the scenes meshed.
  std::shared_ptr<const std::string> meshes;
  uint64_t mesh_version = 0;
  PreviewMeshStats mesh_stats;  // of the last meshing
  double mesh_seconds = 0;      // how long it took
};

class ViewSession {
 public:
  explicit ViewSession(ViewOptions options);
  ~ViewSession();
  ViewSession(const ViewSession&) = delete;
  ViewSession& operator=(const ViewSession&) = delete;

  ViewFrame frame() const;
  // Renders from this camera (checked as a scene file's camera: load_camera_json). Moves that
  // arrive while a preview renders replace each other: the render restarts at most once a
  // preview.
  void set_camera(const CameraDesc& camera);
  // Waits until `until` holds for the frame (true) or the timeout passes (false).
  bool wait(const std::function<bool(const ViewFrame&)>& until, double timeout_seconds) const;

 private:
  using Clock = std::chrono::steady_clock;
  // What a look at a file saw (following links): its kind, which file it is, its time and size.
  // A file replaced by another, or by a FIFO, a directory or a device, stamps differently even
  // when the old stamp was of a failed load, so that the page shows the new reason.
  struct Stamp {
    std::string path;
    int kind = -1;  // the stat mode's file type bits; -1: absent
    uint64_t device = 0, inode = 0;
    int64_t mtime = 0;  // nanoseconds
    int64_t size = -1;
    bool operator==(const Stamp&) const = default;
  };

  void loop();
  // The mesher's thread: meshes each scene loaded, the newest replacing any waiting.
  void mesh_loop();
  // Loads and compiles the scene file; false (with the error published) if it fails.
  bool load();
  bool files_changed() const;
  void restart(Clock::time_point now);
  void render_preview_frame();
  void render_pass();
  void publish(std::shared_ptr<const Image> image, bool preview);
  static Stamp stamp(const std::string& path);

  ViewOptions options_;
  // The render thread's own.
  std::unique_ptr<Scene> scene_;
  CameraDesc file_camera_;  // the camera the scene file gives
  CameraDesc camera_;       // the camera rendered
  std::vector<Stamp> watched_;
  Film film_;
  int spp_ = 0, pass_spp_ = 1;
  uint64_t samples_ = 0;
  double render_seconds_ = 0;
  Clock::time_point restarted_, moved_;
  bool need_preview_ = true;

  // Shared with the callers, under mutex_.
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;  // the frame changed
  std::condition_variable wake_;             // a camera arrived, or stop
  std::optional<CameraDesc> pending_camera_;
  bool stop_ = false;
  ViewFrame frame_;
  std::atomic<bool> interrupt_{false};          // stop, or a camera is pending: cancels a pass
  std::optional<PreviewScene> pending_meshes_;  // a scene loaded and not yet meshed
  std::condition_variable mesh_wake_;           // a scene to mesh, or stop
  std::thread thread_, mesh_thread_;
};

// The noise of a film as one number: over pixels, the root mean square of the standard error of
// their means, the channels' variances weighted as luminance weighs the channels (linear sRGB's
// Y), relative to the image's mean luminance; 0 for a film without two samples a pixel or
// without light.
double view_noise(const Film& film);

}  // namespace nimbus
