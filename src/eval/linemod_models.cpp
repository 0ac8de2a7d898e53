// The LINEMOD meshes on disk: listed per call, read once per process (linemod_models.hpp).
#include "linemod_models.hpp"

#include <proxseg/core/errors.hpp>
#include <proxseg/io/cloud_io.hpp>

#include <algorithm>
#include <filesystem>
#include <map>
#include <mutex>

namespace proxseg::detail {

namespace fs = std::filesystem;

namespace {

struct CachedMesh {
  std::uintmax_t size = 0;
  fs::file_time_type mtime;
  std::shared_ptr<const Mesh> mesh;
};

}  // namespace

std::shared_ptr<const Mesh> cached_mesh(const std::string& path) {
  static std::mutex m;
  static std::map<std::string, CachedMesh> cache;
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  const fs::file_time_type mtime = fs::last_write_time(path, ec);
  {
    std::lock_guard<std::mutex> lock(m);
    const auto it = cache.find(path);
    if (it != cache.end() && it->second.size == size && it->second.mtime == mtime)
      return it->second.mesh;
  }
  auto mesh = std::make_shared<const Mesh>(read_mesh(path, 0.001));  // millimetres
  std::lock_guard<std::mutex> lock(m);
  cache[path] = {size, mtime, mesh};
  return mesh;
}

std::vector<std::string> list_models(const std::string& dir) {
  std::vector<std::string> out;
  if (dir.empty()) return out;
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError(dir + ": models folder not found (expected LINEMOD obj_*.ply meshes)");
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("obj_", 0) == 0 && e.path().extension() == ".ply")
      out.push_back(e.path().string());
  }
  if (ec) throw InputError(dir + ": cannot list the models folder (" + ec.message() + ")");
  if (out.empty()) throw InputError(dir + ": no obj_*.ply meshes in the models folder");
  std::sort(out.begin(), out.end());
  return out;
}

Mesh linemod_mesh(const std::string& dir, const std::string& id, const std::string& needed_by) {
  const fs::path path = fs::path(dir) / (id + ".ply");
  if (!fs::is_regular_file(path))
    throw InputError(path.string() + ": missing (" + needed_by + " needs the LINEMOD mesh)");
  return read_mesh(path.string(), 0.001);
}

}  // namespace proxseg::detail
