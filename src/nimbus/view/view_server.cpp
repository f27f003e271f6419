#include "nimbus/view/view_server.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <microhttpd.h>
#include <netdb.h>
#include <strings.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

#include "nimbus/io/output.h"
#include "nimbus/io/png.h"
#include "nimbus/scene/json_reader.h"
#include "nimbus/view/camera_body.h"
#include "nimbus/view/connection_table.h"
#include "nimbus/view/loopback.h"

namespace nimbus {
namespace {

constexpr size_t kMaxBody = 16 * 1024;     // a camera is a few hundred bytes
constexpr size_t kMaxHeaders = 16 * 1024;  // a connection's buffer: the request line and headers

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

// One answer: its status, body, type and extra headers.
struct Answer {
  unsigned status = 200;
  std::string body;
  const char* type = "application/json";
  std::vector<std::pair<std::string, std::string>> headers;
  // A body shared with the session (the meshes, megabytes): sent from where it is, not copied.
  std::shared_ptr<const std::string> shared_body = nullptr;
};

Answer error(unsigned status, const std::string& message) {
  return {
      status, nlohmann::json{{"error", printable_line(message)}}.dump(), "application/json", {}};
}

// A request's own state between the handler's calls: its body so far.
struct Request {
  std::string body;
  bool too_big = false;
};

int socket_of(MHD_Connection* c) {
  const MHD_ConnectionInfo* info = MHD_get_connection_info(c, MHD_CONNECTION_INFO_CONNECTION_FD);
  return info ? info->connect_fd : -1;
}

std::string header(MHD_Connection* c, const char* name) {
  const char* v = MHD_lookup_connection_value(c, MHD_HEADER_KIND, name);
  return v ? v : "";
}

int count_headers(MHD_Connection* c, const char* name) {
  struct Count {
    const char* name;
    int n;
  } count{name, 0};
  MHD_get_connection_values(
      c, MHD_HEADER_KIND,
      [](void* cls, MHD_ValueKind, const char* key, const char*) {
        auto* k = static_cast<Count*>(cls);
        if (strcasecmp(key, k->name) == 0) ++k->n;
        return MHD_YES;
      },
      &count);
  return count.n;
}

std::string address_text(const sockaddr* a) {
  char text[NI_MAXHOST] = "";
  const socklen_t size = a->sa_family == AF_INET6 ? sizeof(sockaddr_in6) : sizeof(sockaddr_in);
  getnameinfo(a, size, text, sizeof text, nullptr, 0, NI_NUMERICHOST);
  return text;
}

}  // namespace

struct ViewServer::Impl {
  ViewSession& session;
  ViewServerOptions options;
  int listen_socket = -1;
  int port = 0;
  bool loopback = true;
  // The PNG of the frame last asked for, by version: several pages, one encoding.
  std::mutex png_mutex;
  uint64_t png_version = ~uint64_t{0};
  std::string png;
  std::atomic<uint64_t> saves{0};  // names each save's temporary file
  // The connections, and serve()'s loop that drops those past their deadline.
  std::mutex mutex;
  std::condition_variable wake;
  ConnectionTable connections{ConnectionTable::Limits{}};
  bool stopping = false;

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
            {"pixels_done", f.pixels_done},
            {"error", f.error},
            {"loads", f.loads},
            {"restarts", f.restarts},
            {"camera", camera_json(f.camera)},
            {"meshes", f.mesh_version},
            {"mesh_triangles", f.mesh_stats.triangles},
            {"mesh_seconds", f.mesh_seconds}};
  }

  // The film's image, written as `nimbus render` writes it, through a private temporary file.
  Answer save(const std::string& extension) {
    const ViewFrame f = session.frame();
    if (!f.film_image)
      return error(409, "nothing to save yet: the render has no samples (the camera moved)");
    const std::filesystem::path dir = std::filesystem::temp_directory_path();
    const std::string path =
        (dir / fmt::format("nimbus-view-{}-{}.{}", getpid(), saves++, extension)).string();
    write_image(path, *f.film_image);
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    std::filesystem::remove(path);
    return {200,
            bytes.str(),
            extension == "png" ? "image/png" : "image/x-exr",
            {{"Content-Disposition", fmt::format("attachment; filename=\"{}-{}spp.{}\"",
                                                 options.name, f.spp, extension)}}};
  }

  Answer camera(const Request& r) {
    if (r.too_big) return error(413, fmt::format("request body over {} bytes", kMaxBody));
    try {
      session.set_camera(parse_camera_body(r.body));
    } catch (const SceneError& e) {
      return error(400, e.what());
    }
    return {200, R"({"ok":true})", "application/json", {}};
  }

  // The answer to a request, or none yet. Called once its headers have arrived (body_done
  // false), where only a camera's headers are looked at, so that one that will be refused is
  // refused before its body comes; and again once its body has come. An answer given on the
  // first call ends the connection after it (libmicrohttpd cannot know where the next request
  // starts), so requests without a body are answered on the second, which keeps connections
  // alive and pipelined requests answered.
  std::optional<Answer> route(MHD_Connection* c, std::string_view method, std::string_view url,
                              const Request& r, bool body_done) {
    const bool camera_move = method == "POST" && url == "/camera";
    if (!body_done && !camera_move) return std::nullopt;
    // HTTP allows one Host; two could make this check and a proxy disagree on whose it is.
    if (count_headers(c, "Host") > 1)
      return error(400, "two Host headers: a request names one host");
    if (loopback && !loopback_host_header(header(c, "Host"), port))
      return error(403, "this server answers to its loopback address only");
    const bool get = method == "GET" || method == "HEAD";
    if (get && url == "/") return Answer{200, kViewerHtml, "text/html; charset=utf-8", {}};
    if (get && url == "/viewer.js")
      return Answer{200, kViewerJs, "text/javascript; charset=utf-8", {}};
    if (get && url == "/meshes.js")
      return Answer{200, kViewerMeshesJs, "text/javascript; charset=utf-8", {}};
    if (get && url == "/viewer.css") return Answer{200, kViewerCss, "text/css; charset=utf-8", {}};
    if (get && url == "/state") return Answer{200, state().dump(), "application/json", {}};
    if (get && url == "/image.png") {
      const ViewFrame f = session.frame();
      if (!f.image) return error(404, "no image yet");
      return Answer{
          200, image_png(f), "image/png", {{"X-Nimbus-Version", std::to_string(f.version)}}};
    }
    if (get && url == "/meshes.bin") {
      const ViewFrame f = session.frame();
      if (!f.meshes) return error(404, "no meshes yet");
      return Answer{200,
                    {},
                    "application/octet-stream",
                    {{"X-Nimbus-Meshes", std::to_string(f.mesh_version)}},
                    f.meshes};
    }
    if (get && url == "/save.exr") return save("exr");
    if (get && url == "/save.png") return save("png");
    if (camera_move) {
      // JSON only: a page of another site cannot send it without the browser asking first.
      if (header(c, "Content-Type").rfind("application/json", 0) != 0)
        return error(415, "a camera is sent as application/json");
      const std::string length = header(c, "Content-Length");
      if (length.size() > 9 || (!length.empty() && std::stoul(length) > kMaxBody))
        return error(413, fmt::format("request body over {} bytes", kMaxBody));
      if (!body_done) return std::nullopt;
      return camera(r);
    }
    return error(404, fmt::format("{} {}: not found", method, url));
  }

  MHD_Result answer(MHD_Connection* c, Answer a) {
    // The response keeps the body alive until the server has sent it, then frees it.
    auto* body = new std::shared_ptr<const std::string>(
        a.shared_body ? std::move(a.shared_body)
                      : std::make_shared<const std::string>(std::move(a.body)));
    MHD_Response* response = MHD_create_response_from_buffer_with_free_callback_cls(
        (*body)->size(), const_cast<char*>((*body)->data()),
        [](void* kept) { delete static_cast<std::shared_ptr<const std::string>*>(kept); }, body);
    if (!response) {
      delete body;
      return MHD_NO;
    }
    MHD_add_response_header(response, "Content-Type", a.type);
    MHD_add_response_header(response, "Cache-Control", "no-store");
    for (const auto& [name, value] : a.headers)
      MHD_add_response_header(response, name.c_str(), value.c_str());
    const MHD_Result queued = MHD_queue_response(c, a.status, response);
    MHD_destroy_response(response);
    std::lock_guard lock(mutex);
    connections.answering(socket_of(c), ConnectionTable::Clock::now());
    return queued;
  }

  MHD_Result answer_route(MHD_Connection* c, std::string_view method, std::string_view url,
                          const Request& r, bool body_done) {
    try {
      const std::optional<Answer> a = route(c, method, url, r, body_done);
      return a ? answer(c, std::move(*a)) : MHD_YES;
    } catch (const std::exception& e) {
      return answer(c, error(500, e.what()));
    }
  }

  // libmicrohttpd's access handler: called once the headers have arrived, then for each piece
  // of the body, then once more when the body is complete.
  MHD_Result handle(MHD_Connection* c, const char* url, const char* method, const char* upload_data,
                    size_t* upload_size, void** context) {
    auto* r = static_cast<Request*>(*context);
    if (!r) {
      *context = r = new Request;
      return answer_route(c, method, url, *r, false);
    }
    if (*upload_size > 0) {
      if (r->body.size() + *upload_size > kMaxBody)
        r->too_big = true;  // a body sent without Content-Length, or longer than it said
      else
        r->body.append(upload_data, *upload_size);
      *upload_size = 0;
      return MHD_YES;
    }
    return answer_route(c, method, url, *r, true);
  }

  // A connection opens (kept, or dropped with others to make room) or closes. The table drops
  // a socket by shutting it down, which libmicrohttpd sees as the client leaving; it closes a
  // socket only after telling us (MHD_CONNECTION_NOTIFY_CLOSED), which waits for this lock, so
  // a socket number is never shut down after it was reused.
  void notify(MHD_Connection* c, MHD_ConnectionNotificationCode code) {
    const int socket = socket_of(c);
    std::lock_guard lock(mutex);
    if (code == MHD_CONNECTION_NOTIFY_CLOSED) return connections.remove(socket);
    const MHD_ConnectionInfo* info = MHD_get_connection_info(c, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
    const std::string client = info && info->client_addr ? address_text(info->client_addr) : "?";
    for (int s : connections.add(socket, client, ConnectionTable::Clock::now()))
      ::shutdown(s, SHUT_RDWR);
    wake.notify_all();
  }

  void completed(MHD_Connection* c, void** context) {
    delete static_cast<Request*>(*context);
    *context = nullptr;
    const int socket = socket_of(c);
    std::lock_guard lock(mutex);
    connections.answered(socket, ConnectionTable::Clock::now());
  }

  void serve() {
    const unsigned workers = unsigned(std::max(options.workers, 2));
    MHD_Daemon* daemon = MHD_start_daemon(
        MHD_USE_EPOLL_INTERNAL_THREAD, 0, nullptr, nullptr,
        [](void* self, MHD_Connection* c, const char* url, const char* method, const char*,
           const char* data, size_t* size, void** context) {
          return static_cast<Impl*>(self)->handle(c, url, method, data, size, context);
        },
        this, MHD_OPTION_LISTEN_SOCKET, listen_socket, MHD_OPTION_THREAD_POOL_SIZE, workers,
        // The table keeps fewer; this bounds connections it has dropped and not yet seen close.
        MHD_OPTION_CONNECTION_LIMIT, unsigned(2 * ConnectionTable::Limits{}.total),
        MHD_OPTION_CONNECTION_MEMORY_LIMIT, kMaxHeaders, MHD_OPTION_STRICT_FOR_CLIENT, 1,
        MHD_OPTION_NOTIFY_CONNECTION,
        static_cast<MHD_NotifyConnectionCallback>(
            [](void* self, MHD_Connection* c, void**, MHD_ConnectionNotificationCode code) {
              static_cast<Impl*>(self)->notify(c, code);
            }),
        this, MHD_OPTION_NOTIFY_COMPLETED,
        static_cast<MHD_RequestCompletedCallback>(
            [](void* self, MHD_Connection* c, void** context, MHD_RequestTerminationCode) {
              static_cast<Impl*>(self)->completed(c, context);
            }),
        this, MHD_OPTION_END);
    if (!daemon) throw std::runtime_error("the web server did not start (libmicrohttpd)");
    listen_socket = -1;  // the daemon's now: it closes it
    std::unique_lock lock(mutex);
    while (!stopping) {
      const auto now = ConnectionTable::Clock::now();
      for (int s : connections.expired(now)) ::shutdown(s, SHUT_RDWR);
      wake.wait_until(lock, std::min(connections.next_deadline(), now + std::chrono::seconds(1)));
    }
    lock.unlock();
    MHD_stop_daemon(daemon);
  }
};

ViewServer::ViewServer(ViewSession& session, ViewServerOptions options)
    : impl_(std::make_unique<Impl>(session, std::move(options))) {}

ViewServer::~ViewServer() {
  if (impl_->listen_socket >= 0) ::close(impl_->listen_socket);
}

int ViewServer::bind() {
  const auto& o = impl_->options;
  const auto fail = [&](const std::string& problem) {
    return std::runtime_error(fmt::format("{}:{}: {}", o.host, o.port, problem));
  };
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  if (getaddrinfo(o.host.c_str(), std::to_string(o.port).c_str(), &hints, &found) != 0 || !found)
    throw fail("cannot listen there (the host is not this machine's)");
  const std::unique_ptr<addrinfo, decltype(&freeaddrinfo)> owned(found, freeaddrinfo);
  impl_->loopback = is_loopback(found->ai_addr);
  if (!impl_->loopback && !o.allow_remote)
    throw fail(
        "not a loopback address: the viewer would be served beyond this machine "
        "(--allow-remote allows it)");
  const int s = ::socket(found->ai_family, found->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK,
                         found->ai_protocol);
  const int on = 1;
  if (s < 0 || setsockopt(s, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on) != 0 ||
      ::bind(s, found->ai_addr, found->ai_addrlen) != 0 || ::listen(s, 128) != 0) {
    if (s >= 0) ::close(s);
    throw fail("cannot listen there (the port is in use, or the host is not this machine's)");
  }
  sockaddr_storage bound{};
  socklen_t size = sizeof bound;
  getsockname(s, reinterpret_cast<sockaddr*>(&bound), &size);
  impl_->port =
      ntohs(bound.ss_family == AF_INET6 ? reinterpret_cast<const sockaddr_in6&>(bound).sin6_port
                                        : reinterpret_cast<const sockaddr_in&>(bound).sin_port);
  impl_->listen_socket = s;
  return impl_->port;
}

bool ViewServer::loopback() const {
  return impl_->loopback;
}

void ViewServer::serve() {
  impl_->serve();
}

void ViewServer::stop() {
  std::lock_guard lock(impl_->mutex);
  impl_->stopping = true;
  impl_->wake.notify_all();
}

}  // namespace nimbus
