// Frames of a dataset for batch work (frame_source.hpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/frame_source.hpp>

#include <fnmatch.h>

#include <functional>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <stdexcept>

#include "io/input_file.hpp"

namespace proxseg {
namespace fs = std::filesystem;
namespace {

std::string lower_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool is_cloud(const fs::path& p) {
  const std::string ext = lower_extension(p);
  return ext == ".pcd" || ext == ".ply";
}

fs::path normal(const fs::path& p) {
  return fs::absolute(p).lexically_normal();
}

// A naming pattern split at its one {id}: prefix, suffix.
struct Pattern {
  std::string prefix, suffix;
  std::string with(const std::string& id) const { return prefix + id + suffix; }
};

Pattern parse_pattern(const std::string& pattern, const char* what) {
  const auto at = pattern.find("{id}");
  if (at == std::string::npos || pattern.find("{id}", at + 1) != std::string::npos)
    throw InputError(std::string(what) + " naming pattern " + pattern +
                     " must hold {id} exactly once (e.g. {id}-color.png or rgb/{id}.png)");
  return {pattern.substr(0, at), pattern.substr(at + 4)};
}

// If path (generic, '/'-separated) matches the colour pattern: the frame's path without the
// pattern's parts (the folder the patterns are relative to, then the id) and the id.
bool match_pattern(const Pattern& p, const std::string& path, std::string& base, std::string& id) {
  if (path.size() <= p.suffix.size() ||
      path.compare(path.size() - p.suffix.size(), p.suffix.size(), p.suffix) != 0)
    return false;
  const std::string stem = path.substr(0, path.size() - p.suffix.size());
  const auto slash = p.prefix.rfind('/');
  const std::string pdir = slash == std::string::npos ? "" : p.prefix.substr(0, slash + 1);
  const std::string pfile = p.prefix.substr(pdir.size());
  const auto cut = stem.rfind('/');
  const std::string dir = cut == std::string::npos ? "" : stem.substr(0, cut + 1);
  const std::string name = stem.substr(dir.size());
  if (name.size() <= pfile.size() || name.compare(0, pfile.size(), pfile) != 0) return false;
  if (dir.size() < pdir.size() || dir.compare(dir.size() - pdir.size(), pdir.size(), pdir) != 0)
    return false;
  if (dir.size() > pdir.size() && !pdir.empty() && dir[dir.size() - pdir.size() - 1] != '/')
    return false;
  base = dir.substr(0, dir.size() - pdir.size());
  id = name.substr(pfile.size());
  return true;
}

// Frames found so far, keyed by their path without extension (absolute), before ids are made.
struct Found {
  fs::path key;
  FrameSource source;
  std::string origin;  // what found it, for error messages
};

class Collector {
 public:
  explicit Collector(const RgbdNaming& naming)
      : naming_(naming),
        colour_(parse_pattern(naming.colour, "colour")),
        depth_(parse_pattern(naming.depth, "depth")),
        meta_(naming.meta.empty() ? Pattern{} : parse_pattern(naming.meta, "meta")) {}

  // A file found in a folder or by a glob, or named by a list: kept if it is a frame.
  bool add_file(const fs::path& file, const std::string& origin) {
    const fs::path p = normal(file);
    if (is_cloud(p)) {
      FrameSource s;
      s.cloud = p.string();
      found_.push_back({fs::path(p).replace_extension(), s, origin});
      return true;
    }
    std::string base, id;
    if (!match_pattern(colour_, p.generic_string(), base, id)) return false;
    FrameSource s;
    s.colour = p.string();
    s.depth = fs::path(base + depth_.with(id)).string();
    if (!naming_.meta.empty() && fs::is_regular_file(base + meta_.with(id)))
      s.camera = fs::path(base + meta_.with(id)).string();
    else if (!naming_.intrinsics.empty())
      s.camera = normal(naming_.intrinsics).string();
    found_.push_back({fs::path(base + id), s, origin});
    return true;
  }

  // A folder entry that cannot be read (walk): a frame that fails, when it is named like one or
  // may have been one (a link that leads nowhere, a folder that cannot be listed).
  void add_unreadable(const fs::path& entry, const std::string& why, bool always,
                      const std::string& origin) {
    const fs::path p = normal(entry);
    std::string base, id;
    fs::path key;
    if (is_cloud(p))
      key = fs::path(p).replace_extension();
    else if (match_pattern(colour_, p.generic_string(), base, id))
      key = base + id;
    else if (always)
      key = p;
    else
      return;
    FrameSource s;
    s.unreadable = p.string();
    s.problem = why;
    found_.push_back({key, s, origin});
  }

  // A list line "COLOR DEPTH [CAMERA]" (relative to the list's folder).
  void add_pair(const fs::path& dir, const std::vector<std::string>& f, const std::string& origin) {
    FrameSource s;
    s.colour = normal(dir / f[0]).string();
    s.depth = normal(dir / f[1]).string();
    if (f.size() == 3)
      s.camera = normal(dir / f[2]).string();
    else if (!naming_.intrinsics.empty())
      s.camera = normal(naming_.intrinsics).string();
    // Named like the colour pattern: the pattern's id; else the image's name.
    std::string base, id;
    const fs::path key = match_pattern(colour_, fs::path(s.colour).generic_string(), base, id)
                             ? fs::path(base + id)
                             : fs::path(s.colour).replace_extension();
    found_.push_back({key, s, origin});
  }

  std::vector<Found>& found() { return found_; }

 private:
  const RgbdNaming& naming_;
  Pattern colour_, depth_, meta_;
  std::vector<Found> found_;
};

bool hidden(const fs::path& p) {
  const std::string name = p.filename().string();
  return name.size() > 1 && name[0] == '.';
}

// An entry of a folder that is neither a regular file nor a folder to walk into.
struct Unreadable {
  fs::path path;
  std::string why;  // not_a_regular_file's words, or why the folder cannot be listed
  bool always;      // a frame even when not named like one (a dangling link or a link loop
                    // may have been anything; a folder that cannot be listed may hold frames)
};

// What walk finds under a folder: its regular files (sorted), and the entries it cannot read.
struct Walk {
  std::vector<fs::path> files;
  std::vector<Unreadable> unreadable;
};

// Walks dir recursively (hidden entries skipped, links to folders not followed); an entry that
// cannot be read is noted and the walk goes on.
void walk_into(const fs::path& dir, Walk& w) {
  std::error_code ec;
  fs::directory_iterator it(dir, ec), end;
  if (ec) {
    w.unreadable.push_back({dir, "cannot read the folder (" + ec.message() + ")", true});
    return;
  }
  for (; it != end; it.increment(ec)) {
    if (ec) {
      w.unreadable.push_back({dir, "cannot read the folder (" + ec.message() + ")", true});
      return;
    }
    const fs::path& p = it->path();
    if (hidden(p)) continue;
    std::error_code link_ec, st_ec;
    const fs::file_status link = it->symlink_status(link_ec);
    const fs::file_status st = it->status(st_ec);
    if (fs::is_symlink(link) && (st_ec || st.type() == fs::file_type::not_found)) {
      w.unreadable.push_back({p, detail::not_a_regular_file(p.string()), true});
    } else if (fs::is_directory(link)) {
      walk_into(p, w);
    } else if (fs::is_regular_file(st)) {
      w.files.push_back(p);
    } else if (!fs::is_directory(st)) {  // a FIFO, socket or device (or a link to one)
      w.unreadable.push_back({p, detail::not_a_regular_file(p.string()), false});
    }
  }
}

Walk walk(const fs::path& dir) {
  Walk w;
  std::error_code ec;
  fs::directory_iterator probe(dir, ec);
  if (ec) throw FileError(dir.string() + ": cannot read the folder (" + ec.message() + ")");
  walk_into(dir, w);
  std::sort(w.files.begin(), w.files.end());
  return w;
}

// Every frame of a walk into c.
void add_walk(const Walk& w, const std::string& origin, Collector& c) {
  for (const fs::path& f : w.files) c.add_file(f, origin);
  for (const Unreadable& u : w.unreadable) c.add_unreadable(u.path, u.why, u.always, origin);
}

bool has_wildcard(const std::string& s) {
  return s.find_first_of("*?[") != std::string::npos;
}

std::vector<std::string> split(const std::string& path) {
  std::vector<std::string> parts;
  for (const auto& part : fs::path(path)) parts.push_back(part.string());
  return parts;
}

// Components of a relative path against a glob's: fnmatch per component, "**" any number.
bool glob_match(const std::vector<std::string>& pat, std::size_t i,
                const std::vector<std::string>& path, std::size_t j) {
  if (i == pat.size()) return j == path.size();
  if (pat[i] == "**") {
    for (std::size_t k = j; k <= path.size(); ++k)
      if (glob_match(pat, i + 1, path, k)) return true;
    return false;
  }
  return j < path.size() && fnmatch(pat[i].c_str(), path[j].c_str(), FNM_PERIOD) == 0 &&
         glob_match(pat, i + 1, path, j + 1);
}

void add_glob(const std::string& glob, Collector& c) {
  // The folder before the first component with a wildcard is walked; the rest is matched.
  const std::vector<std::string> parts = split(glob);
  fs::path root;
  std::size_t first = 0;
  while (first < parts.size() && !has_wildcard(parts[first])) root /= parts[first++];
  if (root.empty()) root = ".";
  const std::vector<std::string> pattern(parts.begin() + static_cast<long>(first), parts.end());
  std::error_code ec;
  if (!fs::is_directory(root, ec))
    throw FileError(glob + ": no folder " + root.string() + " (expected a glob of existing files)");
  Walk w = walk(root);
  const auto matches = [&](const fs::path& f) {
    return glob_match(pattern, 0, split(f.lexically_relative(root).string()), 0);
  };
  w.files.erase(std::remove_if(w.files.begin(), w.files.end(), std::not_fn(matches)),
                w.files.end());
  w.unreadable.erase(std::remove_if(w.unreadable.begin(), w.unreadable.end(),
                                    [&](const Unreadable& u) { return !matches(u.path); }),
                     w.unreadable.end());
  add_walk(w, glob, c);
}

void add_list(const fs::path& list, Collector& c) {
  std::istringstream in(detail::read_input_file(list.string()));
  const fs::path dir = list.parent_path();
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto last = line.find_last_not_of(" \t\r");
    const std::string entry = line.substr(first, last - first + 1);
    const std::string where = list.string() + ":" + std::to_string(n);
    std::error_code ec;
    if (fs::is_regular_file(dir / entry, ec)) {
      if (!c.add_file(dir / entry, where))
        throw InputError(where + ": " + entry +
                         " is neither a .pcd/.ply cloud nor a colour image named like the colour "
                         "pattern (expected a frame, or \"COLOR DEPTH [CAMERA.json]\")");
      continue;
    }
    std::istringstream words(entry);
    std::vector<std::string> f;
    for (std::string w; words >> w;) f.push_back(w);
    if (f.size() == 1)
      throw FileError(where + ": " + entry + ": " +
                      detail::not_a_regular_file((dir / entry).string()));
    if (f.size() > 3)
      throw InputError(where + ": " + std::to_string(f.size()) +
                       " words (expected a frame, or \"COLOR DEPTH [CAMERA.json]\")");
    c.add_pair(dir, f, where);
  }
}

}  // namespace

bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) &&
        std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t ie = i, je = j;
      while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
      while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
      // Without leading zeros, the longer run is the larger number.
      std::size_t is = i, js = j;
      while (is + 1 < ie && a[is] == '0') ++is;
      while (js + 1 < je && b[js] == '0') ++js;
      if (ie - is != je - js) return ie - is < je - js;
      const int c = a.compare(is, ie - is, b, js, je - js);
      if (c != 0) return c < 0;
      i = ie, j = je;
      continue;
    }
    if (a[i] != b[j]) return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]);
    ++i, ++j;
  }
  if (a.size() - i != b.size() - j) return a.size() - i < b.size() - j;
  return a < b;
}

namespace {

fs::path common_folder(const std::vector<Found>& found) {
  fs::path common = found.front().key.parent_path();
  for (const Found& f : found) {
    const fs::path dir = f.key.parent_path();
    auto a = common.begin(), b = dir.begin();
    fs::path shared;
    for (; a != common.end() && b != dir.end() && *a == *b; ++a, ++b) shared /= *a;
    common = shared;
  }
  return common;
}

}  // namespace

std::vector<std::string> FrameSource::files() const {
  if (!unreadable.empty()) return {unreadable};
  if (!cloud.empty()) return {cloud};
  std::vector<std::string> f = {colour, depth};
  if (!camera.empty()) f.push_back(camera);
  return f;
}

std::vector<FrameSource> discover_frames(const std::vector<std::string>& sources,
                                         const RgbdNaming& naming) {
  if (sources.empty()) throw InputError("no input given (expected a folder, list file or glob)");
  Collector c(naming);
  fs::path root;
  for (const std::string& source : sources) {
    std::error_code ec;
    if (has_wildcard(source) && !fs::exists(source, ec)) {
      add_glob(source, c);
    } else if (fs::is_directory(source, ec)) {
      add_walk(walk(source), source, c);
      if (sources.size() == 1) root = normal(source);
    } else if (fs::is_regular_file(source, ec)) {
      if (!c.add_file(source, source)) add_list(source, c);  // a frame, else a list of them
    } else if (fs::symlink_status(source, ec).type() != fs::file_type::not_found) {
      throw FileError(source + ": " + detail::not_a_regular_file(source) +
                      "; expected a folder, a list file, a glob or a .pcd/.ply file");
    } else {
      throw FileError(source +
                      ": no such file or folder (expected a folder, a list file, a glob or a "
                      ".pcd/.ply file)");
    }
  }
  std::vector<Found>& found = c.found();
  // A colour pattern as wide as "{id}.png" also matches the depth images: those are not frames.
  std::set<std::string> depths;
  for (const Found& f : found)
    if (!f.source.depth.empty()) depths.insert(normal(f.source.depth).string());
  found.erase(std::remove_if(found.begin(), found.end(),
                             [&](const Found& f) {
                               return !f.source.colour.empty() && depths.count(f.source.colour);
                             }),
              found.end());
  std::string what;
  for (const auto& s : sources) what += (what.empty() ? "" : ", ") + s;
  if (found.empty())
    throw InputError(what + ": no frames (expected .pcd/.ply clouds or RGB-D pairs named " +
                     naming.colour + " and " + naming.depth + ")");
  if (root.empty()) root = common_folder(found);
  std::map<std::string, const Found*> ids;
  std::vector<FrameSource> frames;
  for (const Found& f : found) {
    FrameSource s = f.source;
    s.id = f.key.lexically_relative(root).generic_string();
    const auto [it, fresh] = ids.emplace(s.id, &f);
    if (!fresh)
      throw InputError(what + ": two frames named " + s.id + " (" + it->second->source.files()[0] +
                       " and " + s.files()[0] +
                       "): their outputs would overwrite each other (expected one frame per name)");
    frames.push_back(std::move(s));
  }
  std::sort(frames.begin(), frames.end(),
            [](const FrameSource& a, const FrameSource& b) { return natural_less(a.id, b.id); });
  return frames;
}

std::vector<FrameSource> shard_frames(const std::vector<FrameSource>& frames, int index,
                                      int count) {
  if (count < 1 || index < 1 || index > count)
    throw InputError("shard " + std::to_string(index) + "/" + std::to_string(count) +
                     " (expected I/N with 1 <= I <= N)");
  std::vector<FrameSource> mine;
  for (const FrameSource& f : frames) {
    std::uint64_t h = 14695981039346656037ull;  // FNV-1a, 64 bits
    for (unsigned char ch : f.id) h = (h ^ ch) * 1099511628211ull;
    if (static_cast<int>(h % static_cast<std::uint64_t>(count)) == index - 1) mine.push_back(f);
  }
  return mine;
}

Intrinsics read_camera(const std::string& path) {
  const nlohmann::json j = nlohmann::json::parse(detail::read_input_file(path), nullptr, false);
  if (j.is_object() && j.contains("intrinsic_matrix")) return read_ycb_meta(path);
  return read_intrinsics(path);
}

Frame read_frame(const FrameSource& s) {
  if (!s.unreadable.empty()) throw FileError(s.unreadable + ": " + s.problem);
  if (!s.cloud.empty()) return read_point_cloud(s.cloud);
  if (s.camera.empty())
    throw InputError(s.colour +
                     ": no camera for this RGB-D pair (expected a meta file named like the meta "
                     "pattern beside it, or one intrinsics JSON for all pairs)");
  return read_rgbd(s.colour, s.depth, read_camera(s.camera));
}

}  // namespace proxseg
