#pragma once
// Running the nimbus executable from a test, in a directory of the test's own: in a shell (exit
// code, stderr and stdout), or spawned in the background to be signalled.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace nimbus::test {

struct Ran {
  int code = -1;
  std::string err;
  std::string out;
};

// A fresh, empty directory for the running test: <tmp>/<prefix>_<pid>_<test name>.
inline std::filesystem::path fresh_test_dir(const std::string& prefix) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      (prefix + "_" + std::to_string(::getpid()) + "_" +
       ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Runs `command` with sh in `dir`: its exit code, stderr and stdout (kept in two files there
// while it runs, removed after).
inline Ran run_in(const std::filesystem::path& dir, const std::string& command) {
  const std::filesystem::path out_file = dir / "stdout.txt", err_file = dir / "stderr.txt";
  const std::string cmd = "cd '" + dir.string() + "' && " + command + " >'" + out_file.string() +
                          "' 2>'" + err_file.string() + "'";
  const int status = std::system(cmd.c_str());
  const auto take = [](const std::filesystem::path& path) {
    std::ifstream f(path);
    std::stringstream ss;
    ss << f.rdbuf();
    f.close();
    std::filesystem::remove(path);
    return ss.str();
  };
  std::string out = take(out_file);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, take(err_file), std::move(out)};
}

// Runs the nimbus executable with `args` in `dir`.
inline Ran run_nimbus_in(const std::filesystem::path& dir, const std::string& args) {
  return run_in(dir, std::string("'") + NIMBUS_BINARY + "' " + args);
}

// Starts `argv` in `dir` with stdout and stderr to /dev/null; returns its pid.
inline pid_t spawn_in(const std::filesystem::path& dir, const std::vector<std::string>& argv) {
  // Built before fork(): between fork and exec the child makes system calls only, no allocation
  // (another thread may have held the allocator's lock at the fork).
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    if (chdir(dir.c_str()) != 0) _exit(127);
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, 1);
    dup2(null, 2);
    execv(args[0], args.data());
    _exit(127);
  }
  return pid;
}

// Waits until `path` exists, polling, for at most a minute; whether it does.
inline bool wait_for_file(const std::filesystem::path& path) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!std::filesystem::exists(path)) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

// The exit status of a spawned process as a shell reports it: the code, or 128 + the signal.
inline int wait_for(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

inline std::string file_bytes(const std::filesystem::path& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// Whether two files hold the same bytes (a test prints names, not megabytes, when they differ).
inline bool same_bytes(const std::filesystem::path& a, const std::filesystem::path& b) {
  return file_bytes(a) == file_bytes(b);
}

}  // namespace nimbus::test
