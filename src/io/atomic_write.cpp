// Atomic writes (write_file_atomic, write_files_atomic in cloud_io.hpp): the bytes go to a
// temporary file beside the target, flushed to disk, then renamed over it, so that a reader (or a
// batch resumed after a crash) sees the old file or the new one, never a part.
#include <proxseg/io/cloud_io.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "io/reader_errors.hpp"

namespace fs = std::filesystem;

namespace proxseg {
namespace {

using detail::fail_file;

// The first half of an atomic write: bytes in a temporary file beside path, flushed to disk.
// Returns the temporary file's path; the caller renames it over path (or removes it).
fs::path write_beside(const std::string& path, const std::string& bytes) {
  const fs::path target(path);
  if (!target.has_filename())
    fail_file(path, "cannot write (the path names a directory, expected a file name)");
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    fail_file(path, "cannot write (directory " + dir.string() + " does not exist)");
  static std::atomic<unsigned> counter{0};
  const fs::path tmp = dir / ("." + target.filename().string() + ".tmp." +
                              std::to_string(::getpid()) + "." + std::to_string(counter++));
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) fail_file(path, std::string("cannot write (") + std::strerror(errno) + ")");
  auto give_up = [&](const std::string& reason) {
    ::close(fd);
    std::error_code ignore;
    fs::remove(tmp, ignore);
    fail_file(path, "cannot write (" + reason + ")");
  };
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t w = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (w < 0) {
      if (errno == EINTR) continue;
      give_up(std::strerror(errno));
    }
    done += static_cast<std::size_t>(w);
  }
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) give_up(std::strerror(errno));
  if (::close(fd) != 0) {
    const std::string reason = std::strerror(errno);
    std::error_code ignore;
    fs::remove(tmp, ignore);
    fail_file(path, "cannot write (" + reason + ")");
  }
  return tmp;
}

}  // namespace

void write_file_atomic(const std::string& path, const std::string& bytes) {
  const fs::path tmp = write_beside(path, bytes);
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignore;
    fs::remove(tmp, ignore);
    fail_file(path, "cannot write (" + ec.message() + ")");
  }
}

void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files) {
  // A directory in the way would only show at its rename, after the others had replaced their
  // targets: refused before anything is written.
  for (const auto& [path, bytes] : files) {
    std::error_code ec;
    if (fs::is_directory(path, ec))
      fail_file(path, "cannot write (a directory of that name exists)");
  }
  std::vector<fs::path> temps;
  std::size_t renamed = 0;
  try {
    for (const auto& [path, bytes] : files) temps.push_back(write_beside(path, bytes));
    for (; renamed < files.size(); ++renamed) {
      std::error_code ec;
      fs::rename(temps[renamed], files[renamed].first, ec);
      if (ec) fail_file(files[renamed].first, "cannot write (" + ec.message() + ")");
    }
  } catch (...) {
    // Every file not yet in place goes, and so do the new ones already in place: never a set
    // of which some files are new and others missing.
    std::error_code ignore;
    for (std::size_t i = 0; i < temps.size(); ++i)
      fs::remove(i < renamed ? fs::path(files[i].first) : temps[i], ignore);
    throw;
  }
}

}  // namespace proxseg

namespace proxseg {

void check_writable_folder(const std::string& dir) {
  const fs::path folder = dir.empty() ? fs::path(".") : fs::path(dir);
  static std::atomic<unsigned> counter{0};
  // A file made and removed at once: the one test that a write will work, whatever forbids it
  // (permissions, a read-only mount, a folder of /proc or /sys, an ACL, a full inode table).
  for (int attempt = 0;; ++attempt) {
    const fs::path probe =
        folder / (".proxseg-probe." + std::to_string(::getpid()) + "." + std::to_string(counter++));
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd >= 0) {
      ::close(fd);
      ::unlink(probe.c_str());
      return;
    }
    // A probe of the same name (left by a killed process of the same id): another name.
    if ((errno == EEXIST || errno == EINTR) && attempt < 100) continue;
    const int error = errno;
    throw FileError(
        folder.string() + ": cannot write in the output folder (" + std::strerror(error) + ")",
        error);
  }
}

}  // namespace proxseg
