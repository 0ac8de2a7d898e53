// Point clouds told apart by their content rather than by their name (cloud_io.hpp): bytes held
// in memory and standard input (the command line's "-"), PCD or PLY.
#include <proxseg/io/cloud_io.hpp>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string_view>

#include "io/formats/pcd_reader.hpp"
#include "io/formats/ply_io.hpp"
#include "io/reader_errors.hpp"

namespace proxseg {
namespace {

using detail::fail;

enum class CloudKind { kPcd, kPly, kNeither, kUnknownYet };

// The keywords a PCD header's lines start with.
bool pcd_keyword(std::string_view word) {
  for (std::string_view k : {"VERSION", "FIELDS", "SIZE", "TYPE", "COUNT", "WIDTH", "HEIGHT",
                             "VIEWPOINT", "POINTS", "DATA"})
    if (word == k) return true;
  return false;
}

// What the first bytes of a cloud say it is: its first line "ply" (a PLY), or comment lines and
// then a PCD keyword (a PCD); kUnknownYet while no line that tells is complete.
CloudKind kind_of(std::string_view bytes, bool ended) {
  std::size_t pos = 0;
  for (bool first = true;; first = false) {
    const std::size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos && !ended) return CloudKind::kUnknownYet;
    std::string_view line = bytes.substr(pos, end == std::string_view::npos ? end : end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (first && line == "ply") return CloudKind::kPly;
    if (!line.empty() && line[0] != '#')
      return pcd_keyword(line.substr(0, line.find_first_of(" \t"))) ? CloudKind::kPcd
                                                                    : CloudKind::kNeither;
    if (end == std::string_view::npos) return CloudKind::kNeither;  // only comments
    pos = end + 1;
  }
}

[[noreturn]] void neither(const std::string& name) {
  fail(name,
       "is neither a PCD nor a PLY cloud (expected a PCD header, VERSION, FIELDS, ..., or the "
       "line 'ply' first)");
}

Frame ply_of(const std::string& bytes, const std::string& name) {
  try {
    return detail::ply_cloud(name, detail::parse_ply(bytes));
  } catch (const InputError&) {
    throw;
  } catch (const std::runtime_error& e) {
    fail(name, detail::one_line(e.what()));
  }
}

// Standard input read by need: bytes holds what was read so far.
struct StdinBytes {
  std::string bytes;
  bool ended = false;
  // Reads until bytes holds n bytes or the input ends.
  const std::string& first(std::size_t n) {
    char block[1 << 16];
    while (!ended && bytes.size() < n) {
      const ssize_t got = ::read(STDIN_FILENO, block, std::min(sizeof block, n - bytes.size()));
      if (got < 0 && errno == EINTR) continue;
      if (got < 0)
        detail::fail_file(kStdinName, std::string("read error (") + std::strerror(errno) + ")");
      if (got == 0) ended = true;
      bytes.append(block, static_cast<std::size_t>(got));
    }
    return bytes;
  }
};

// The first line that tells the kind is looked for in this many bytes.
constexpr std::size_t kKindBytes = std::size_t{1} << 16;

}  // namespace

Frame read_point_cloud_bytes(const std::string& bytes, const std::string& name) {
  switch (kind_of(bytes, true)) {
    case CloudKind::kPcd:
      return detail::read_pcd_from(name, [&](std::size_t) -> const std::string& { return bytes; });
    case CloudKind::kPly:
      return ply_of(bytes, name);
    default:
      neither(name);
  }
}

Frame read_point_cloud_stdin() {
  if (::isatty(STDIN_FILENO))
    fail(kStdinName, "is a terminal (expected a PCD or PLY cloud piped or redirected in)");
  StdinBytes in;
  // Line by line up to kKindBytes: a small block at a time until the kind shows.
  CloudKind kind = CloudKind::kUnknownYet;
  for (std::size_t n = 256; kind == CloudKind::kUnknownYet && n <= kKindBytes; n *= 2)
    kind = kind_of(in.first(n), in.ended);
  if (kind == CloudKind::kPcd)
    return detail::read_pcd_from(kStdinName,
                                 [&](std::size_t n) -> const std::string& { return in.first(n); });
  if (kind != CloudKind::kPly) {
    if (in.bytes.empty()) fail(kStdinName, "is empty (expected a PCD or PLY cloud)");
    neither(kStdinName);
  }
  return ply_of(in.first(std::string::npos), kStdinName);
}

}  // namespace proxseg
