#include "nimbus/io/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace nimbus {
namespace {

std::string errno_text() {
  return std::strerror(errno);
}

// The temporaries that exist now, for remove_temporary_files_now: fixed slots of plain chars,
// claimed and released with atomics, so a signal handler can read them at any moment.
constexpr int kSlots = 64;
constexpr size_t kSlotBytes = 4096;
std::array<std::atomic<bool>, kSlots> slot_used{};
std::array<std::array<char, kSlotBytes>, kSlots> slot_path{};

int register_temp(const std::string& temp) {
  if (temp.size() >= kSlotBytes) return -1;
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (!slot_used[i].load() && slot_used[i].compare_exchange_strong(expected, true)) {
      std::memcpy(slot_path[i].data(), temp.c_str(), temp.size() + 1);
      return i;
    }
  }
  return -1;  // more than kSlots at once: still removed on every ordinary path
}

void release_temp(const std::string& temp) {
  for (int i = 0; i < kSlots; ++i)
    if (slot_used[i].load() && temp == slot_path[i].data()) {
      slot_used[i].store(false);
      return;
    }
}

void remove_temp(const std::string& temp) {
  std::remove(temp.c_str());
  release_temp(temp);
}

// Removes the temporaries of `path` left by runs that no longer exist (killed outright, so no
// handler ran): "NAME.tmp-PID-N" whose process is gone.
void remove_leftovers_of(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  const std::string prefix = target.filename().string() + ".tmp-";
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string rest = name.substr(prefix.size());
    const size_t dash = rest.find('-');
    if (dash == std::string::npos || dash == 0) continue;
    char* end_of_pid = nullptr;
    const long pid = std::strtol(rest.c_str(), &end_of_pid, 10);
    if (end_of_pid != rest.c_str() + dash || pid <= 0) continue;
    if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) fs::remove(it->path(), ec);
  }
}

// Creates a temporary file named after `path` and returns its name. O_EXCL makes the name ours
// alone even when several threads or processes write next to each other; mode 0666 lets the
// umask decide the final permissions, as for any newly created file.
std::string create_temp_next_to(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  remove_leftovers_of(path);
  for (int attempt = 0; attempt < 100; ++attempt) {
    const std::string temp =
        path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter.fetch_add(1));
    register_temp(temp);
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      return temp;
    }
    const int error = errno;
    release_temp(temp);
    if (error != EEXIST)
      throw std::runtime_error(path + ": cannot create file: " + std::strerror(error));
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

void rename_into_place(const std::string& temp, const std::string& path) {
  if (std::rename(temp.c_str(), path.c_str()) != 0)
    throw std::runtime_error("cannot rename the written file into place: " + errno_text());
  release_temp(temp);
}

thread_local OutputTransaction* current_transaction = nullptr;

}  // namespace

void write_atomically(const std::string& path,
                      const std::function<void(const std::string& temp_path)>& write_to) {
  const std::string temp = create_temp_next_to(path);
  try {
    write_to(temp);
    sync_to_disk(temp);
    if (current_transaction)
      current_transaction->stage(temp, path);
    else
      rename_into_place(temp, path);
  } catch (const std::exception& e) {
    remove_temp(temp);
    throw std::runtime_error(path + ": " + e.what());
  }
}

OutputTransaction::OutputTransaction() : outer_(current_transaction) {
  current_transaction = this;
}

OutputTransaction::~OutputTransaction() {
  current_transaction = outer_;
  for (const auto& [temp, path] : staged_) remove_temp(temp);
}

void OutputTransaction::stage(std::string temp, std::string path) {
  staged_.emplace_back(std::move(temp), std::move(path));
}

void OutputTransaction::commit() {
  std::vector<std::pair<std::string, std::string>> staged = std::move(staged_);
  staged_.clear();
  for (size_t i = 0; i < staged.size(); ++i) {
    try {
      rename_into_place(staged[i].first, staged[i].second);
    } catch (const std::exception& e) {
      for (size_t k = i; k < staged.size(); ++k) remove_temp(staged[k].first);
      throw std::runtime_error(staged[i].second + ": " + e.what());
    }
  }
}

void remove_temporary_files_now() {
  for (int i = 0; i < kSlots; ++i)
    if (slot_used[i].load()) ::unlink(slot_path[i].data());
}

}  // namespace nimbus
