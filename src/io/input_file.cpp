// Input files as the readers take them (input_file.hpp): regular files only, read whole by one
// descriptor.
#include "io/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>
#include <utility>

namespace proxseg::detail {
namespace {

// The kind of a file that is not regular, by its mode.
std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "is a directory (expected a file)";
  if (S_ISFIFO(mode)) return "is a FIFO (expected a regular file)";
  if (S_ISCHR(mode)) return "is a character device (expected a regular file)";
  if (S_ISBLK(mode)) return "is a block device (expected a regular file)";
  if (S_ISSOCK(mode)) return "is a socket (expected a regular file)";
  return "is not a regular file";
}

// Why stat() of path failed, told apart for the links that cause it.
std::string stat_failure(const std::string& path, int error) {
  struct stat link {};
  if (error == ELOOP) return "is a symbolic link loop (expected a regular file)";
  if (error == ENOENT && ::lstat(path.c_str(), &link) == 0 && S_ISLNK(link.st_mode))
    return "is a dangling symbolic link (expected a regular file)";
  if (error == ENOENT) return "file not found (expected an existing file)";
  return std::string("cannot access (") + std::strerror(error) + ")";
}

struct Descriptor {
  int fd = -1;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

// not_a_regular_file, and the errno that goes with it (EISDIR for a directory).
std::pair<std::string, int> regular_file_problem(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int error = errno;
    return {stat_failure(path, error), error};
  }
  if (S_ISREG(st.st_mode)) return {"", 0};
  return {kind_of(st.st_mode), S_ISDIR(st.st_mode) ? EISDIR : 0};
}

}  // namespace

std::string not_a_regular_file(const std::string& path) {
  return regular_file_problem(path).first;
}

void require_regular_file(const std::string& path) {
  if (const auto [why, error] = regular_file_problem(path); !why.empty())
    throw FileError(path + ": " + why, error);
}

std::string read_input_file(const std::string& path, std::size_t max_bytes) {
  // O_NONBLOCK: opening a FIFO without a writer returns at once instead of waiting for one.
  Descriptor in{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
  if (in.fd < 0) {
    const int error = errno;
    if (const auto [why, code] = regular_file_problem(path); !why.empty())
      throw FileError(path + ": " + why, code);
    throw FileError(path + ": cannot open (" + std::strerror(error) + ")", error);
  }
  struct stat st {};
  if (::fstat(in.fd, &st) != 0)
    throw FileError(path + ": cannot access (" + std::strerror(errno) + ")");
  if (!S_ISREG(st.st_mode))
    throw FileError(path + ": " + kind_of(st.st_mode), S_ISDIR(st.st_mode) ? EISDIR : 0);
  const std::size_t size = static_cast<std::size_t>(st.st_size);
  std::string bytes(std::min(size, max_bytes), '\0');
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(in.fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw FileError(path + ": read error (" + std::strerror(errno) + ")");
    if (n == 0) break;  // shorter than its size said: it shrank while read
    done += static_cast<std::size_t>(n);
  }
  bytes.resize(done);
  return bytes;
}

}  // namespace proxseg::detail
