#include "nimbus/io/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace nimbus {
namespace {

std::string errno_text() {
  return std::strerror(errno);
}

// Creates a temporary file named after `path` and returns its name. O_EXCL makes the name ours
// alone even when several threads or processes write next to each other; mode 0666 lets the
// umask decide the final permissions, as for any newly created file.
std::string create_temp_next_to(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  for (int attempt = 0; attempt < 100; ++attempt) {
    const std::string temp =
        path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter.fetch_add(1));
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      return temp;
    }
    if (errno != EEXIST) throw std::runtime_error(path + ": cannot create file: " + errno_text());
  }
  throw std::runtime_error(path + ": cannot create a temporary file");
}

// Without this, a crash soon after the rename could leave an empty file under the new name.
void sync_to_disk(const std::string& temp) {
  const int fd = ::open(temp.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error("cannot reopen the written file: " + errno_text());
  const int rc = ::fsync(fd);
  const std::string error = rc != 0 ? errno_text() : "";
  ::close(fd);
  if (rc != 0) throw std::runtime_error("cannot flush the written file: " + error);
}

}  // namespace

void write_atomically(const std::string& path,
                      const std::function<void(const std::string& temp_path)>& write_to) {
  const std::string temp = create_temp_next_to(path);
  try {
    write_to(temp);
    sync_to_disk(temp);
    if (std::rename(temp.c_str(), path.c_str()) != 0)
      throw std::runtime_error("cannot rename the written file into place: " + errno_text());
  } catch (const std::exception& e) {
    std::remove(temp.c_str());
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace nimbus
