// The LINEMOD meshes on disk (../shared/data/lmo/models, obj_*.ply in millimetres) as the
// generated scenes and object sets use them: the folder's list, one mesh by id, and a per-process
// cache. Private to the library.
#pragma once
#include <proxseg/core/mesh.hpp>

#include <memory>
#include <string>
#include <vector>

namespace proxseg::detail {

// The obj_*.ply files of a folder, sorted; none for an empty dir. InputError if the folder is
// missing or holds no obj_*.ply.
std::vector<std::string> list_models(const std::string& dir);

// A mesh read once per process (cache keyed by path, size, mtime), in metres.
std::shared_ptr<const Mesh> cached_mesh(const std::string& path);

// DIR/<id>.ply in metres; InputError "...: missing (<needed_by> needs the LINEMOD mesh)".
Mesh linemod_mesh(const std::string& dir, const std::string& id, const std::string& needed_by);

}  // namespace proxseg::detail
