#include "nimbus/io/display_server.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/types.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <string_view>

#include "nimbus/scene/json_reader.h"

namespace nimbus {
namespace {

enum PacketType : std::uint8_t { kCreateImage = 4, kUpdateImage = 6 };

constexpr double kRetrySeconds = 2;     // between attempts to reach an absent viewer
constexpr int kConnectTimeoutMs = 200;  // a viewer on another host may take this long to answer
constexpr int kSendTimeoutSeconds = 2;  // a viewer that stops reading is dropped after this

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Little-endian packet writer into a reused buffer: tev's wire format.
struct Packet {
  std::vector<std::uint8_t>& bytes;
  explicit Packet(std::vector<std::uint8_t>& buffer) : bytes(buffer) { bytes.assign(4, 0); }
  template <class T>
  void put(T value) {
    const size_t at = bytes.size();
    bytes.resize(at + sizeof(T));
    std::memcpy(bytes.data() + at, &value, sizeof(T));  // x86-64 and aarch64 are little-endian
  }
  void put_string(const std::string& s) {
    bytes.insert(bytes.end(), s.begin(), s.end());
    bytes.push_back(0);
  }
  std::vector<std::uint8_t>& done() {
    const auto n = static_cast<std::uint32_t>(bytes.size());
    std::memcpy(bytes.data(), &n, 4);
    return bytes;
  }
};

// Only what the means need is copied: the sums and the counts (2 MB for 320 x 240 pixels).
void stage(Film& to, const Film& film) {
  to.width = film.width;
  to.height = film.height;
  to.exponent = film.exponent;
  to.sum = film.sum;
  to.samples = film.samples;
}

}  // namespace

DisplayAddress parse_display_address(const std::string& address) {
  const auto problem = [&](const std::string& what) {
    return std::invalid_argument(
        fmt::format("\"{}\" {} (expected HOST:PORT, e.g. 127.0.0.1:{} or [::1]:{})",
                    printable_line(address), what, kTevPort, kTevPort));
  };
  if (address.empty())
    throw std::invalid_argument(
        fmt::format("an empty address (expected HOST:PORT, e.g. 127.0.0.1:{})", kTevPort));
  DisplayAddress a;
  std::string rest;
  if (address[0] == '[') {
    const auto close = address.find(']');
    if (close == std::string::npos) throw problem("has no ']' after the IPv6 address");
    a.host = address.substr(1, close - 1);
    if (a.host.find(':') == std::string::npos) throw problem("has no IPv6 address in brackets");
    rest = address.substr(close + 1);
    if (rest.empty() || rest[0] != ':') throw problem("has no ':' and port after the ']'");
    rest.erase(0, 1);
  } else {
    const auto colon = address.rfind(':');
    if (colon == std::string::npos) throw problem("has no ':' before a port");
    a.host = address.substr(0, colon);
    rest = address.substr(colon + 1);
    if (a.host.find(':') != std::string::npos)
      throw problem("has an IPv6 address outside brackets");
    if (a.host.empty()) throw problem("has no host before the ':'");
  }
  // Names, IPv4 and IPv6 addresses (with a zone, fe80::1%eth0) use these characters only.
  for (const char c : a.host)
    if (!std::isalnum(static_cast<unsigned char>(c)) &&
        std::string_view(".-_:%").find(c) == std::string_view::npos)
      throw problem("has a host with a character no host name has");
  if (rest.empty()) throw problem("has no port after the ':'");
  if (rest.find_first_not_of("0123456789") != std::string::npos || rest.size() > 5 ||
      std::stoi(rest) < 1 || std::stoi(rest) > 65535)
    throw problem("has a port that is not a number in [1, 65535]");
  a.port = rest;
  return a;
}

DisplayServer::DisplayServer(const std::string& address, std::string name,
                             std::function<void(const std::string&)> warn)
    : address_(address), name_(std::move(name)), warn_(std::move(warn)) {
  try {
    const DisplayAddress a = parse_display_address(address);
    host_ = a.host;
    port_ = a.port;
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--display-server: ") + e.what());
  }
  sender_ = std::thread([this] { send_loop(); });
}

DisplayServer::~DisplayServer() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  sender_.join();
  if (socket_ >= 0) ::close(socket_);
}

void DisplayServer::send_loop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return pending_ || stop_; });
    if (stop_) return;
    pending_ = false;
    sending_ = true;
    lock.unlock();
    // An exception must not leave this thread (std::terminate): the viewer is given up instead,
    // as for a lost connection, and the render goes on.
    try {
      send_changes(staged_);
    } catch (const std::exception& e) {
      drop(e.what());
    }
    lock.lock();
    sending_ = false;
    idle_.notify_all();
  }
}

void DisplayServer::update(const Film& film) {
  {
    std::lock_guard lock(mutex_);
    if (pending_ || sending_) return;
    stage(staged_, film);
    pending_ = true;
  }
  wake_.notify_one();
}

void DisplayServer::finish(const Film& film) {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [this] { return !pending_ && !sending_; });
  // The thread waits for the mutex, held here until the last update is sent.
  next_attempt_ = 0;
  send_changes(film);
}

void DisplayServer::drop(const std::string& why) {
  if (socket_ >= 0) ::close(socket_);
  socket_ = -1;
  next_attempt_ = now_seconds() + kRetrySeconds;
  if (!warned_ && warn_)
    warn_("--display-server " + address_ + ": " + why + "; the render goes on without it");
  warned_ = true;
}

bool DisplayServer::connect_once() {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (const int e = ::getaddrinfo(host_.c_str(), port_.c_str(), &hints, &found); e != 0) {
    drop(std::string("cannot resolve the host (") + ::gai_strerror(e) + ")");
    return false;
  }
  std::string why = "no address";
  for (addrinfo* a = found; a; a = a->ai_next) {
    const int s = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (s < 0) continue;
    // Non-blocking connect with a timeout: an unreachable host must not stall the render.
    const int flags = ::fcntl(s, F_GETFL);
    ::fcntl(s, F_SETFL, flags | O_NONBLOCK);
    int error = 0;
    if (::connect(s, a->ai_addr, a->ai_addrlen) != 0) {
      error = errno;
      if (error == EINPROGRESS) {
        pollfd p{s, POLLOUT, 0};
        error = ::poll(&p, 1, kConnectTimeoutMs) == 1 ? 0 : ETIMEDOUT;
        socklen_t len = sizeof(int);
        if (error == 0) ::getsockopt(s, SOL_SOCKET, SO_ERROR, &error, &len);
      }
    }
    if (error == 0) {
      ::fcntl(s, F_SETFL, flags);
      const timeval timeout{kSendTimeoutSeconds, 0};
      ::setsockopt(s, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof timeout);
      socket_ = s;
      ::freeaddrinfo(found);
      return true;
    }
    why = std::strerror(error);
    ::close(s);
  }
  ::freeaddrinfo(found);
  drop("cannot connect (" + why + ")");
  return false;
}

bool DisplayServer::send_all(const std::vector<std::uint8_t>& packet) {
  for (size_t sent = 0; sent < packet.size();) {
    const ssize_t n = ::send(socket_, packet.data() + sent, packet.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) {
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK))
        drop("the viewer stopped reading (nothing taken for " +
             std::to_string(kSendTimeoutSeconds) + " s)");
      else
        drop(std::string("the viewer went away (") + (n < 0 ? std::strerror(errno) : "closed") +
             ")");
      return false;
    }
    sent += size_t(n);
  }
  return true;
}

void DisplayServer::send_changes(const Film& film) {
  const bool fresh = socket_ < 0;
  if (fresh) {
    if (now_seconds() < next_attempt_ || !connect_once()) return;
    Packet create(packet_);
    create.put(kCreateImage);
    create.put<std::uint8_t>(1);  // grab focus
    create.put_string(name_);
    create.put<std::int32_t>(film.width);
    create.put<std::int32_t>(film.height);
    create.put<std::int32_t>(3);
    for (const char* c : {"R", "G", "B"}) create.put_string(c);
    if (!send_all(create.done())) return;
    sent_samples_.assign(size_t(film.pixels()), 0);
  }
  for (int y0 = 0; y0 < film.height; y0 += kDisplayTile) {
    for (int x0 = 0; x0 < film.width; x0 += kDisplayTile) {
      const int w = std::min(kDisplayTile, film.width - x0);
      const int h = std::min(kDisplayTile, film.height - y0);
      bool changed = fresh;
      for (int y = y0; y < y0 + h && !changed; ++y)
        for (int x = x0; x < x0 + w && !changed; ++x)
          changed =
              film.samples[size_t(y) * film.width + x] != sent_samples_[size_t(y) * film.width + x];
      if (!changed) continue;
      Packet tile(packet_);
      tile.put(kUpdateImage);
      tile.put<std::uint8_t>(0);
      tile.put_string(name_);
      tile.put<std::int32_t>(3);
      for (const char* c : {"R", "G", "B"}) tile.put_string(c);
      for (const int v : {x0, y0, w, h}) tile.put<std::int32_t>(v);
      for (std::int64_t c = 0; c < 3; ++c) tile.put<std::int64_t>(c);  // offsets
      for (int c = 0; c < 3; ++c) tile.put<std::int64_t>(3);           // strides
      const size_t data = packet_.size();
      packet_.resize(data + size_t(w) * h * 3 * sizeof(float));
      std::uint8_t* out = packet_.data() + data;
      for (int y = y0; y < y0 + h; ++y)
        for (int x = x0; x < x0 + w; ++x) {
          const int p = y * film.width + x;
          const Rgb m = film.mean(p);  // as to_image converts it
          const float rgb[3] = {float(m[0]), float(m[1]), float(m[2])};
          std::memcpy(out, rgb, sizeof rgb);
          out += sizeof rgb;
          sent_samples_[size_t(p)] = film.samples[size_t(p)];
        }
      if (!send_all(tile.done())) return;
      ++tiles_sent_;
    }
  }
  // The viewer is back once a connection outlives its first update: sends to a new one succeed
  // into the kernel's buffers even where the viewer then resets it, which warned again at each
  // reconnection (issue 44).
  if (!fresh) warned_ = false;
}

}  // namespace nimbus
