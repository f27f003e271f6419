#pragma once
// Running the nimbus executable from a test: in a shell (exit code and stderr), or spawned in
// the background to be signalled.

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace nimbus::testing {

struct Ran {
  int code = -1;
  std::string err;
};

// Runs `command` with sh in `dir`; stdout is dropped.
inline Ran run_in(const std::filesystem::path& dir, const std::string& command) {
  const std::filesystem::path err_file = dir / "stderr.txt";
  const std::string cmd =
      "cd '" + dir.string() + "' && " + command + " >/dev/null 2>'" + err_file.string() + "'";
  const int status = std::system(cmd.c_str());
  std::ifstream f(err_file);
  std::stringstream ss;
  ss << f.rdbuf();
  std::filesystem::remove(err_file);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
}

// Starts `argv` in `dir` with stdout and stderr to /dev/null; returns its pid.
inline pid_t spawn_in(const std::filesystem::path& dir, const std::vector<std::string>& argv) {
  const pid_t pid = fork();
  if (pid == 0) {
    if (chdir(dir.c_str()) != 0) _exit(127);
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, 1);
    dup2(null, 2);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
  }
  return pid;
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

}  // namespace nimbus::testing
