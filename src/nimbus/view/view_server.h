#pragma once
// `nimbus view`'s web server (GNU libmicrohttpd, event-driven): the viewer page and its three
// assets, the session's state as JSON, its image as PNG, camera moves, and the film saved as EXR
// or PNG, and nothing else: no file of the file system is served. Connections cost a socket, not
// a thread: a few threads watch them all (epoll) and run the handlers. Each request is small
// and bounded: a body of at most 16 KiB, headers of at most 16 KiB, 5 s for the whole request to
// arrive and 5 s for its answer to be taken, at most 256 connections and 128 from one address,
// the stalest waiting one dropped for a newcomer (view/connection_table.h). Every handler
// answers a malformed request with a 4xx and a one-line message, so that no client stalls the
// render or the other clients.
//
//   GET  /                 the page          GET  /state       the frame as JSON
//   GET  /viewer.js, /meshes.js, /viewer.css GET  /image.png   the image shown now
//   POST /camera           {"from": ..., "to": ..., ...} (a scene file's camera), JSON only
//   GET  /save.exr, /save.png                the film's image as `nimbus render` writes it
//   GET  /meshes.bin       the objects' meshes, which the page draws while the camera moves
//                          (view/preview_mesh.h)

#include <memory>
#include <string>

#include "nimbus/view/view_session.h"

namespace nimbus {

struct ViewServerOptions {
  std::string host = "127.0.0.1";
  int port = 8080;             // 0: any free port
  bool allow_remote = false;   // serve on an address other than the loopback
  int workers = 4;             // threads that watch connections and run handlers
  std::string name = "scene";  // the scene's name on the page and in saved files' names
};

class ViewServer {
 public:
  ViewServer(ViewSession& session, ViewServerOptions options);
  ~ViewServer();
  ViewServer(const ViewServer&) = delete;
  ViewServer& operator=(const ViewServer&) = delete;
  // Binds to the host and port; returns the port. std::runtime_error("HOST:PORT: problem"),
  // also for an address beyond the loopback without allow_remote.
  int bind();
  // Whether the bound address is the loopback's (bind() first).
  bool loopback() const;
  // Serves until stop() (from another thread or a signal handler's watcher).
  void serve();
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The page and its assets, compiled in (view/page/).
extern const char* const kViewerHtml;
extern const char* const kViewerJs;
extern const char* const kViewerMeshesJs;
extern const char* const kViewerCss;

}  // namespace nimbus
