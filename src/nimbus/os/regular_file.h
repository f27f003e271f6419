#pragma once
// Every file nimbus reads is a regular file (issue 44): a FIFO would block its reader in open,
// /dev/zero would never end, a directory has no bytes. The file is checked before it is opened
// (opening some devices has effects of its own), opened without blocking and checked again by its
// descriptor, so that what is read is what was checked. Readers of our own formats read through
// RegularFile; libraries that take a path (OpenVDB, NanoVDB) get it after check_regular_file.

#include <cstdint>
#include <istream>
#include <memory>
#include <stdexcept>
#include <streambuf>
#include <string>

namespace nimbus {

// "PATH: REASON", the reason also on its own for callers that blame a key instead of the path:
// "not a regular file (a FIFO)", "cannot open file (is a directory)", "cannot open file (No such
// file or directory)", "cannot open file (a symbolic link to a missing file)".
struct FileOpenError : std::runtime_error {
  FileOpenError(const std::string& path, const std::string& reason);
  std::string reason;
};

// The reason `path` cannot be read as a regular file, or "" if it can (as far as a stat sees).
std::string regular_file_problem(const std::string& path);

// Throws FileOpenError unless `path` is a regular file; returns its size.
uint64_t check_regular_file(const std::string& path);

// A regular file open for reading, with a buffered stream over it from its first byte.
class RegularFile {
 public:
  explicit RegularFile(const std::string& path);  // FileOpenError
  ~RegularFile();
  RegularFile(const RegularFile&) = delete;
  RegularFile& operator=(const RegularFile&) = delete;

  const std::string& path() const { return path_; }
  uint64_t size() const { return size_; }  // when opened
  int fd() const { return fd_; }
  std::istream& stream() { return stream_; }

 private:
  class Buffer : public std::streambuf {
   public:
    explicit Buffer(int fd) : fd_(fd) {}

   protected:
    int_type underflow() override;
    pos_type seekoff(off_type off, std::ios_base::seekdir dir,
                     std::ios_base::openmode which) override;
    pos_type seekpos(pos_type pos, std::ios_base::openmode which) override;

   private:
    int fd_;
    char data_[1 << 16];
  };

  std::string path_;
  int fd_ = -1;
  uint64_t size_ = 0;
  std::unique_ptr<Buffer> buffer_;
  std::istream stream_;
};

}  // namespace nimbus
