// Who owns a batch's output folder (batch_settings.hpp): one set of settings, its fingerprint,
// the first difference between two, and the checked start of a run under the folder's lock.
#include "io/batch/batch_settings.hpp"

#include <proxseg/core/errors.hpp>
#include <proxseg/io/batch.hpp>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>
#include <vector>

#include "io/batch/log_lines.hpp"
#include "util/shown_names.hpp"

namespace proxseg {
namespace fs = std::filesystem;

namespace detail {
namespace {

// A value as a message shows it (never throws on bytes that are not UTF-8); "absent" for none.
std::string shown_value(const nlohmann::json* v) {
  return v ? dump_shown(*v) : "absent";
}

// A setting that differs between a and b: its path and both values (nullptr: absent).
struct Differing {
  std::string path;
  const nlohmann::json* a;
  const nlohmann::json* b;
};

// Every leaf (a value that is not an object on both sides) where a and b differ, depth first, in
// key order.
void differing_leaves(const nlohmann::json* a, const nlohmann::json* b, const std::string& path,
                      std::vector<Differing>& out) {
  if (a && b && *a == *b) return;
  if (!(a && b && a->is_object() && b->is_object())) {
    out.push_back({path, a, b});
    return;
  }
  std::set<std::string> keys;
  for (const auto& [key, value] : a->items()) keys.insert(key);
  for (const auto& [key, value] : b->items()) keys.insert(key);
  for (const std::string& key : keys) {
    const auto ia = a->find(key), ib = b->find(key);
    differing_leaves(ia == a->end() ? nullptr : &*ia, ib == b->end() ? nullptr : &*ib,
                     path + "/" + key, out);
  }
}

// Whether a difference follows from others: paper_labels is turned on by every flag of stages
// 2-4 (apps/param_flags.cpp), so it differs along with the parameter that was given.
bool derived(const Differing& d) {
  const std::string name = "/paper_labels";
  return d.path.size() >= name.size() &&
         d.path.compare(d.path.size() - name.size(), name.size(), name) == 0;
}

// Whether another process holds a log open for writing (SummaryLog's exclusive flock).
bool in_use(const std::string& log) {
  const int fd = ::open(log.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool busy = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);
  return busy;
}

}  // namespace

nlohmann::json batch_settings(const nlohmann::json& header) {
  nlohmann::json s = nlohmann::json::object();
  for (const char* key : {"command", "database", "outputs", "parameters"})
    s[key] = header.is_object() ? header.value(key, nlohmann::json()) : nlohmann::json();
  return s;
}

std::string settings_difference(const nlohmann::json& a, const nlohmann::json& b,
                                const std::string& name_a, const std::string& name_b) {
  const nlohmann::json sa = batch_settings(a), sb = batch_settings(b);
  std::vector<Differing> all;
  differing_leaves(&sa, &sb, "", all);
  if (all.empty()) return "";
  std::stable_partition(all.begin(), all.end(), [](const Differing& d) { return !derived(d); });
  const Differing& first = all.front();
  // paper_labels alone: the flag that turned it on is not in the settings, so say which do.
  const std::string why =
      derived(first) ? "; every flag of stages 2-4, e.g. --voxel-size, turns it on" : "";
  std::string text = first.path.substr(1) + " (" + shown_value(first.a) + " " + name_a + ", " +
                     shown_value(first.b) + " " + name_b + why + ")";
  if (all.size() > 1) text += " and " + std::to_string(all.size() - 1) + " more";
  return text;
}

FolderGate::FolderGate(const std::string& out_dir)
    : path_((fs::path(out_dir) / ".proxseg-batch.lock").string()) {
  for (;;) {
    fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd_ < 0)
      throw FileError(
          path_ + ": cannot make the output folder's lock (" + std::strerror(errno) + ")", errno);
    int locked;
    while ((locked = ::flock(fd_, LOCK_EX)) != 0 && errno == EINTR) {
    }
    if (locked != 0) {
      const int error = errno;
      ::close(fd_);
      throw FileError(path_ + ": cannot lock the output folder (" + std::strerror(error) + ")",
                      error);
    }
    // Its holder removes the file when done (no file is left in the folder): the lock won is
    // the folder's only while the file at the path is still the one locked; else take anew.
    struct stat held, now;
    if (::fstat(fd_, &held) == 0 && ::stat(path_.c_str(), &now) == 0 && held.st_dev == now.st_dev &&
        held.st_ino == now.st_ino)
      return;
    ::close(fd_);
  }
}

FolderGate::~FolderGate() {
  ::unlink(path_.c_str());  // before the lock goes: a waiting process then takes a new file
  ::close(fd_);
}

void check_folder_settings(const std::string& out_dir, const std::string& own_log,
                           const nlohmann::json& header, bool resume) {
  for (const std::string& log : summary_logs(out_dir)) {
    const std::string name = fs::path(log).filename().string();
    if (name == own_log && !resume && !in_use(log)) continue;  // this run starts it anew
    std::string difference;
    for_each_log_line(
        log,
        [&](nlohmann::json& line, std::size_t number) {
          if (difference.empty() && line.contains("header"))
            if (const std::string d =
                    settings_difference(line["header"], header, "in that batch", "in this run");
                !d.empty())
              difference = "(" + name + ":" + std::to_string(number) + "): " + d;
        },
        [](const std::string&, const std::string&) {});
    if (!difference.empty())
      throw InputError(out_dir + " holds a batch with other settings " + difference +
                       " (expected one set of settings per output folder: give another -o "
                       "folder, or the same settings as that batch)");
  }
}

}  // namespace detail

std::string settings_fingerprint(const nlohmann::json& header) {
  // The settings' canonical text: keys sorted (nlohmann::json's objects are), no spaces, numbers
  // as their shortest round trip, names not UTF-8 shown as \xFF: the same bytes everywhere.
  const std::string text = dump_shown(detail::batch_settings(header));
  std::uint64_t h = 14695981039346656037ull;  // FNV-1a, 64 bits
  for (const char c : text) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ull;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

}  // namespace proxseg
