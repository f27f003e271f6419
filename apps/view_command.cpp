// `nimbus view SCENE`: the scene rendered progressively in a web page (view/view_server.h), with
// camera moves and live reloads, until a signal stops the server.

#include <fmt/format.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "command.h"
#include "nimbus/render/memory_estimate.h"
#include "nimbus/scene/json_reader.h"
#include "nimbus/view/view_server.h"
#include "nimbus/view/view_session.h"
#include "options.h"
#include "stop_signals.h"

namespace {

struct ViewArgs {
  std::string scene;
  std::string host = "127.0.0.1";
  int port = 8080;
  std::vector<std::string> sets;
  int spp = 0;
  std::optional<double> noise_target;
  std::optional<uint64_t> seed;
  int threads = 0;
  std::optional<std::string> max_memory;
  bool allow_remote = false;
  double mesh_error = 1.0 / 256;
};

// Ends `nimbus view` once a signal has come: stops the server at once, and ends the process
// after a grace time even if the render thread does not finish (a scene load stuck in a file
// that never answers, say), as the signal asked. Destroyed, it waits for nothing more.
class ViewSignalWatcher {
 public:
  ViewSignalWatcher() : thread_([this] { watch(); }) {}
  ~ViewSignalWatcher() {
    {
      std::lock_guard lock(mutex_);
      finished_ = true;
    }
    thread_.join();
  }
  void serving(nimbus::ViewServer* server) {
    std::lock_guard lock(mutex_);
    server_ = server;
    if (server_ && stop_signal() != 0) server_->stop();
  }

 private:
  void watch() {
    for (;;) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      std::lock_guard lock(mutex_);
      if (finished_) return;
      if (stop_signal() != 0) break;
    }
    serving(server_);
    constexpr auto kGrace = std::chrono::seconds(2);
    const auto end = std::chrono::steady_clock::now() + kGrace;
    while (std::chrono::steady_clock::now() < end) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      std::lock_guard lock(mutex_);
      if (finished_) return;
    }
    std::fflush(stdout);
    std::_Exit(0);
  }

  std::mutex mutex_;
  nimbus::ViewServer* server_ = nullptr;
  bool finished_ = false;
  std::thread thread_;
};

// `nimbus view`: the scene rendered progressively in a web page (view/view_server.h) until a
// signal stops the server (exit 0).
int run_view(const ViewArgs& args) {
  using namespace nimbus;
  ViewOptions options;
  options.scene = args.scene;
  options.overrides = args.sets;
  options.spp = args.spp;
  options.noise_target = args.noise_target;
  options.seed = args.seed;
  options.threads = args.threads;
  if (!(args.mesh_error >= 0 && args.mesh_error <= 0.25)) {
    std::fprintf(stderr,
                 "nimbus: --mesh-error: must be in [0, 0.25] (a fraction of each object's size; "
                 "0: no meshes), not %g\n",
                 args.mesh_error);
    return kExitBadInput;
  }
  options.mesh_error = args.mesh_error;
  if (args.max_memory) {
    try {
      options.max_memory = parse_memory_size(*args.max_memory);
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "nimbus: --max-memory: %s\n", e.what());
      return kExitBadInput;
    }
  }
  ViewServerOptions server_options;
  server_options.host = args.host;
  server_options.port = args.port;
  server_options.name = std::filesystem::path(args.scene).stem().string();
  server_options.allow_remote = args.allow_remote;
  // Declared first, destroyed last: it watches the session's load and its end too.
  ViewSignalWatcher watcher;
  std::unique_ptr<ViewSession> session;
  try {
    session = std::make_unique<ViewSession>(options);
  } catch (const std::exception& e) {
    if (stop_signal() != 0) return 0;
    std::fprintf(stderr, "nimbus: %s\n", printable_line(e.what()).c_str());
    return kExitBadInput;
  }
  ViewServer server(*session, server_options);
  int port = 0;
  try {
    port = server.bind();
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "nimbus: %s\n", printable_line(e.what()).c_str());
    return kExitBadInput;
  }
  const bool v6 = args.host.find(':') != std::string::npos;
  const std::string address =
      fmt::format("{}{}{}:{}", v6 ? "[" : "", args.host, v6 ? "]" : "", port);
  if (!server.loopback())
    std::fprintf(stderr,
                 "nimbus: warning: serving beyond this machine (--allow-remote): anyone who "
                 "reaches %s sees the scene and can move the camera\n",
                 address.c_str());
  std::printf("nimbus view: http://%s/ (Ctrl-C stops)\n", address.c_str());
  std::fflush(stdout);
  watcher.serving(&server);
  server.serve();
  watcher.serving(nullptr);
  return 0;
}

}  // namespace

Command view_command(CLI::App& app) {
  const auto args = std::make_shared<ViewArgs>();
  CLI::App* view = app.add_subcommand(
      "view", "Render a scene progressively in a web page, with camera moves and live reloads");
  view->add_option("scene", args->scene, "Scene file (JSON), rendered again when saved")
      ->required();
  view->add_option("--port", args->port, "Port to serve on (0: any free port; default 8080)")
      ->check(integer_in(0, 65535));
  view->add_option("--host", args->host,
                   "Address to serve on (default 127.0.0.1: this machine only; any other "
                   "than a loopback address needs --allow-remote)");
  view->add_flag("--allow-remote", args->allow_remote,
                 "Allow a --host beyond the loopback: anyone who reaches it sees the scene and "
                 "can move the camera");
  view->add_option("--spp", args->spp, "Samples per pixel to refine to (default: the scene's)")
      ->check(integer_in(1));
  view->add_option("--noise-target", args->noise_target,
                   "Refine each 8x8 block until its estimated relative error is at most this, "
                   "--spp being the most (overrides integrator.noise_target)")
      ->check(CLI::Range(0.0, 1.0));
  view->add_option("--seed", args->seed, "Random seed (overrides integrator.seed)")
      ->check(unsigned_64());
  view->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->check(integer_in(1, 4096));
  view->add_option("--set", args->sets, "Override a scene key, as for render; repeatable");
  view->add_option("--max-memory", args->max_memory,
                   "Refuse scenes estimated to need more memory than this (as for render)");
  view->add_option("--mesh-error", args->mesh_error,
                   "Error of the meshes the page draws while the camera moves, as a fraction of "
                   "each object's size (default 1/256; 0: no meshes, the server's preview only)");
  return {view, [args](const Cluster&) { return run_view(*args); }, /*stoppable=*/true};
}
