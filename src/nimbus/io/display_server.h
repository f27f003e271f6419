#pragma once
// Streaming a render to the tev viewer (github.com/Tom94/tev) while it runs, as pbrt-v4's
// --display-server does: tev's IPC protocol over TCP, each packet a little-endian uint32 of its
// whole length and a uint8 type; CreateImage with the film's size and channels R, G, B, then
// UpdateImage (the form with channel offsets and strides) for the tiles whose pixels changed.
// A viewer that is absent, refuses or goes away costs one warning line; the render goes on, and
// the stream reconnects (and resends the whole image) when the viewer is back.
// The sending is done by a thread of its own, from a copy of the film's sums, so the render never
// waits for the viewer: converting and sending the demo's 320 x 240 film took 3 ms, 32 times in a
// 12.4 s render (0.8 %), with every render thread idle (issue 28).

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "nimbus/render/film.h"

namespace nimbus {

// tev's own port, for the messages' example.
inline constexpr int kTevPort = 14158;

// HOST:PORT split, the host without an IPv6 literal's brackets.
struct DisplayAddress {
  std::string host, port;
};

// Checks and splits `address`: HOST:PORT, HOST a name or an IPv4 address, or an IPv6 address in
// brackets ([::1]:14158), PORT in [1, 65535]. Throws std::invalid_argument with the problem in
// one line that quotes the address ("\"127.0.0.1:\" has no port after the ':' ..."), for
// --display-server to prefix.
DisplayAddress parse_display_address(const std::string& address);

class DisplayServer {
 public:
  // `address` is HOST:PORT (parse_display_address; std::invalid_argument otherwise, its message
  // starting "--display-server: "); `name` is the image's name in the viewer; `warn` gets the
  // one-line warnings, from the sending thread. Connects lazily, on the first update.
  DisplayServer(const std::string& address, std::string name,
                std::function<void(const std::string&)> warn);
  ~DisplayServer();
  DisplayServer(const DisplayServer&) = delete;
  DisplayServer& operator=(const DisplayServer&) = delete;

  // Hands the film to the sending thread, which sends what changed since the last update (all
  // of it on a new connection): the pixels' means as the image written from the film has them
  // (io/film_image.h). Returns at once; while the thread is still sending an earlier film this
  // one is skipped (the next update carries its changes).
  void update(const Film& film);
  // The last update, with the film written: waits for the thread, then sends as update does, but
  // a viewer that went away is tried again now rather than after the retry interval. Returns
  // when it is sent (or given up on).
  void finish(const Film& film);

  // Tiles sent so far, for the tests and the benchmarks.
  std::uint64_t tiles_sent() const { return tiles_sent_; }

 private:
  void send_loop();
  void send_changes(const Film& film);
  bool connect_once();
  bool send_all(const std::vector<std::uint8_t>& packet);
  void drop(const std::string& why);

  std::string host_, port_, address_, name_;
  std::function<void(const std::string&)> warn_;
  // Owned by the sending thread (by finish once the thread is idle):
  int socket_ = -1;
  bool warned_ = false;      // a warning was given since a connection last outlived an update
  double next_attempt_ = 0;  // steady-clock seconds before which no reconnection is tried
  std::vector<std::uint32_t> sent_samples_;  // per pixel, at the last update sent
  std::vector<std::uint8_t> packet_;         // the packet being written, reused
  std::atomic<std::uint64_t> tiles_sent_ = 0;
  // The hand-over: `staged_` holds the film's sums and counts while `pending_` or `sending_`.
  std::mutex mutex_;
  std::condition_variable wake_, idle_;
  Film staged_;
  bool pending_ = false, sending_ = false, stop_ = false;
  std::thread sender_;
};

// The pixel tiles of a stream: kDisplayTile × kDisplayTile pixels.
inline constexpr int kDisplayTile = 64;

}  // namespace nimbus
