#include "nimbus/view/view_server.h"

#include <fmt/format.h>
#include <httplib.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "nimbus/io/output.h"
#include "nimbus/io/png.h"
#include "nimbus/scene/json_reader.h"
#include "nimbus/scene/load.h"

namespace nimbus {
namespace {

constexpr size_t kMaxBody = 16 * 1024;  // a camera is a few hundred bytes
constexpr time_t kTimeoutSeconds = 5;

nlohmann::json camera_json(const CameraDesc& c) {
  auto vec = [](const Vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); };
  nlohmann::json j = {
      {"type", c.type == CameraDesc::Type::Perspective ? "perspective" : "orthographic"},
      {"from", vec(c.from)},
      {"to", vec(c.to)},
      {"up", vec(c.up)}};
  if (c.type == CameraDesc::Type::Perspective)
    j["fov"] = c.fov;
  else
    j["width"] = c.width;
  return j;
}

void fail(httplib::Response& res, int status, const std::string& message) {
  res.status = status;
  res.set_content(nlohmann::json{{"error", printable_line(message)}}.dump(), "application/json");
}

// A DNS name that resolves to the loopback could otherwise let another web site's page talk to
// the server through the browser: a server bound to the loopback answers only to its own names.
bool loopback(const std::string& host) {
  return host == "127.0.0.1" || host == "localhost" || host == "::1";
}

bool host_header_allowed(const std::string& header, int port) {
  for (const char* name : {"127.0.0.1", "localhost", "[::1]"})
    if (header == fmt::format("{}:{}", name, port) || header == name) return true;
  return false;
}

}  // namespace

struct ViewServer::Impl {
  ViewSession& session;
  ViewServerOptions options;
  httplib::Server server;
  int port = 0;
  // The PNG of the frame last asked for, by version: several pages, one encoding.
  std::mutex png_mutex;
  uint64_t png_version = ~uint64_t{0};
  std::string png;
  std::atomic<uint64_t> saves{0};  // names each save's temporary file

  Impl(ViewSession& s, ViewServerOptions o) : session(s), options(std::move(o)) {}

  std::string image_png(const ViewFrame& f) {
    std::lock_guard lock(png_mutex);
    if (png_version != f.version) {
      png = encode_png(*f.image);
      png_version = f.version;
    }
    return png;
  }

  nlohmann::json state() const {
    const ViewFrame f = session.frame();
    return {{"scene", options.name},
            {"version", f.version},
            {"has_image", f.image != nullptr},
            {"preview", f.preview},
            {"width", f.width},
            {"height", f.height},
            {"spp", f.spp},
            {"target_spp", f.target_spp},
            {"samples_per_second", f.samples_per_second},
            {"elapsed", f.elapsed},
            {"noise", f.noise},
            {"error", f.error},
            {"loads", f.loads},
            {"restarts", f.restarts},
            {"camera", camera_json(f.camera)}};
  }

  // The film's image, written as `nimbus render` writes it, through a private temporary file.
  void save(httplib::Response& res, const std::string& extension) {
    const ViewFrame f = session.frame();
    if (!f.film_image)
      return fail(res, 409, "nothing to save yet: the render has no samples (the camera moved)");
    const std::filesystem::path dir = std::filesystem::temp_directory_path();
    const std::string path =
        (dir / fmt::format("nimbus-view-{}-{}.{}", getpid(), saves++, extension)).string();
    write_image(path, *f.film_image);
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    std::filesystem::remove(path);
    res.set_header("Content-Disposition", fmt::format("attachment; filename=\"{}-{}spp.{}\"",
                                                      options.name, f.spp, extension));
    res.set_content(bytes.str(), extension == "png" ? "image/png" : "image/x-exr");
  }

  void routes() {
    auto page = [](const char* body, const char* type) {
      return [body, type](const httplib::Request&, httplib::Response& res) {
        res.set_content(body, type);
      };
    };
    server.Get("/", page(kViewerHtml, "text/html; charset=utf-8"));
    server.Get("/viewer.js", page(kViewerJs, "text/javascript; charset=utf-8"));
    server.Get("/viewer.css", page(kViewerCss, "text/css; charset=utf-8"));
    server.Get("/state", [this](const httplib::Request&, httplib::Response& res) {
      res.set_content(state().dump(), "application/json");
    });
    server.Get("/image.png", [this](const httplib::Request&, httplib::Response& res) {
      const ViewFrame f = session.frame();
      if (!f.image) return fail(res, 404, "no image yet");
      res.set_header("X-Nimbus-Version", std::to_string(f.version));
      res.set_content(image_png(f), "image/png");
    });
    server.Get("/save.exr",
               [this](const httplib::Request&, httplib::Response& res) { save(res, "exr"); });
    server.Get("/save.png",
               [this](const httplib::Request&, httplib::Response& res) { save(res, "png"); });
    server.Post("/camera", [this](const httplib::Request& req, httplib::Response& res) {
      // JSON only: a page of another site cannot send it without the browser asking first.
      if (req.get_header_value("Content-Type").rfind("application/json", 0) != 0)
        return fail(res, 415, "a camera is sent as application/json");
      nlohmann::json body;
      try {
        body = nlohmann::json::parse(req.body);
      } catch (const nlohmann::json::parse_error& e) {
        return fail(res, 400, fmt::format("camera: not JSON ({})", e.what()));
      }
      try {
        session.set_camera(load_camera_json(body, "camera"));
      } catch (const SceneError& e) {
        return fail(res, 400, e.what());
      }
      res.set_content(R"({"ok":true})", "application/json");
    });
    server.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
      res.set_header("Cache-Control", "no-store");
      if (loopback(options.host) && !host_header_allowed(req.get_header_value("Host"), port)) {
        fail(res, 403, "this server answers to its loopback address only");
        return httplib::Server::HandlerResponse::Handled;
      }
      return httplib::Server::HandlerResponse::Unhandled;
    });
    server.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
      if (!res.body.empty()) return;
      if (res.status == 404)
        fail(res, 404, fmt::format("{} {}: not found", req.method, req.path));
      else if (res.status == 413)
        fail(res, 413, fmt::format("request body over {} bytes", kMaxBody));
      else
        fail(res, res.status, fmt::format("{} {}: refused", req.method, req.path));
    });
    server.set_exception_handler(
        [](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
          try {
            std::rethrow_exception(ep);
          } catch (const std::exception& e) {
            fail(res, 500, e.what());
          } catch (...) {
            fail(res, 500, "unknown error");
          }
        });
    server.set_payload_max_length(kMaxBody);
    server.set_read_timeout(kTimeoutSeconds, 0);
    server.set_write_timeout(kTimeoutSeconds, 0);
    server.set_keep_alive_timeout(kTimeoutSeconds);
    const int workers = options.workers;
    server.new_task_queue = [workers] { return new httplib::ThreadPool(size_t(workers)); };
  }
};

ViewServer::ViewServer(ViewSession& session, ViewServerOptions options)
    : impl_(std::make_unique<Impl>(session, std::move(options))) {
  impl_->routes();
}

ViewServer::~ViewServer() {
  stop();
}

int ViewServer::bind() {
  const auto& o = impl_->options;
  const int port = o.port == 0 ? impl_->server.bind_to_any_port(o.host)
                               : (impl_->server.bind_to_port(o.host, o.port) ? o.port : -1);
  if (port < 0)
    throw std::runtime_error(fmt::format(
        "{}:{}: cannot listen there (the port is in use, or the host is not this machine's)",
        o.host, o.port));
  impl_->port = port;
  return port;
}

void ViewServer::serve() {
  impl_->server.listen_after_bind();
}

void ViewServer::stop() {
  if (impl_->server.is_running()) impl_->server.stop();
}

}  // namespace nimbus
