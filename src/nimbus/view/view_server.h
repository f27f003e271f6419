#pragma once
// `nimbus view`'s web server (cpp-httplib): the viewer page and its two assets, the session's
// state as JSON, its image as PNG, camera moves, and the film saved as EXR or PNG, and nothing
// else: no file of the file system is served. Each request is small and bounded (a body of at
// most 16 KiB, 5 s to read or write a request, a fixed pool of workers), and every handler
// answers a malformed request with a 4xx and a one-line message, so that no client stalls the
// render or the other clients.
//
//   GET  /                 the page          GET  /state       the frame as JSON
//   GET  /viewer.js, /viewer.css             GET  /image.png   the image shown now
//   POST /camera           {"from": ..., "to": ..., ...} (a scene file's camera), JSON only
//   GET  /save.exr, /save.png                the film's image as `nimbus render` writes it

#include <memory>
#include <string>

#include "nimbus/view/view_session.h"

namespace nimbus {

struct ViewServerOptions {
  std::string host = "127.0.0.1";
  int port = 8080;             // 0: any free port
  int workers = 8;             // connections served at once; more wait for a worker
  std::string name = "scene";  // the scene's name on the page and in saved files' names
};

class ViewServer {
 public:
  ViewServer(ViewSession& session, ViewServerOptions options);
  ~ViewServer();
  // Binds to the host and port; returns the port. std::runtime_error("HOST:PORT: problem").
  int bind();
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
extern const char* const kViewerCss;

}  // namespace nimbus
