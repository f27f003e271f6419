#include "nimbus/os/regular_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace nimbus {
namespace {

std::string kind(mode_t mode) {
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a file";
}

// The reason a file of this status is not read; "" for a regular file.
std::string mode_problem(mode_t mode) {
  if (S_ISREG(mode)) return "";
  if (S_ISDIR(mode)) return "cannot open file (is a directory)";
  return "not a regular file (" + kind(mode) + ")";
}

std::string open_problem(const std::string& path, int error) {
  struct stat link;
  if (error == ENOENT && ::lstat(path.c_str(), &link) == 0 && S_ISLNK(link.st_mode))
    return "cannot open file (a symbolic link to a missing file)";
  return std::string("cannot open file (") + std::strerror(error) + ")";
}

}  // namespace

FileOpenError::FileOpenError(const std::string& path, const std::string& reason_)
    : std::runtime_error(path + ": " + reason_), reason(reason_) {}

std::string regular_file_problem(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) return open_problem(path, errno);
  return mode_problem(st.st_mode);
}

uint64_t check_regular_file(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) throw FileOpenError(path, open_problem(path, errno));
  if (const std::string p = mode_problem(st.st_mode); !p.empty()) throw FileOpenError(path, p);
  return uint64_t(st.st_size);
}

RegularFile::RegularFile(const std::string& path) : path_(path), stream_(nullptr) {
  check_regular_file(path);
  // O_NONBLOCK: should a FIFO take the file's place after the check, open does not wait for a
  // writer, and fstat below refuses it.
  fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) throw FileOpenError(path, open_problem(path, errno));
  struct stat st;
  std::string problem =
      ::fstat(fd_, &st) != 0 ? open_problem(path, errno) : mode_problem(st.st_mode);
  if (problem.empty() && ::fcntl(fd_, F_SETFL, 0) != 0) problem = open_problem(path, errno);
  if (!problem.empty()) {
    ::close(fd_);
    throw FileOpenError(path, problem);
  }
  size_ = uint64_t(st.st_size);
  buffer_ = std::make_unique<Buffer>(fd_);
  stream_.rdbuf(buffer_.get());
}

RegularFile::~RegularFile() {
  if (fd_ >= 0) ::close(fd_);
}

RegularFile::Buffer::int_type RegularFile::Buffer::underflow() {
  if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
  ssize_t n;
  do n = ::read(fd_, data_, sizeof data_);
  while (n < 0 && errno == EINTR);
  if (n <= 0) return traits_type::eof();  // a read error ends the stream; readers say "cut short"
  setg(data_, data_, data_ + n);
  return traits_type::to_int_type(*gptr());
}

RegularFile::Buffer::pos_type RegularFile::Buffer::seekoff(off_type off, std::ios_base::seekdir dir,
                                                           std::ios_base::openmode) {
  off_t at;
  if (dir == std::ios_base::cur) {
    // The descriptor is ahead of the stream by what the buffer still holds.
    at = ::lseek(fd_, off_t(off) - (egptr() - gptr()), SEEK_CUR);
  } else {
    at = ::lseek(fd_, off_t(off), dir == std::ios_base::beg ? SEEK_SET : SEEK_END);
  }
  if (at < 0) return pos_type(off_type(-1));
  setg(data_, data_, data_);
  return pos_type(off_type(at));
}

RegularFile::Buffer::pos_type RegularFile::Buffer::seekpos(pos_type pos,
                                                           std::ios_base::openmode which) {
  return seekoff(off_type(pos), std::ios_base::beg, which);
}

}  // namespace nimbus
