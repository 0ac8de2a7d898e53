// A mesh's size against its units (mesh_units.hpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>
#include <proxseg/io/mesh_units.hpp>

#include <cstdio>

namespace proxseg {

void check_mesh_units(const Mesh& mesh, const std::string& path, const std::string& units,
                      const std::string& flag) {
  if (mesh.vertices.empty()) return;
  Eigen::Vector3f lo = mesh.vertices.front(), hi = lo;
  for (const Eigen::Vector3f& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const double size = (hi - lo).norm();  // metres
  char what[64];
  std::snprintf(what, sizeof what, "%.4g m across with ", size);
  const std::string given = path + ": " + what + flag + (flag.back() == '=' ? "" : " ") + units;
  const std::string other = flag + (flag.back() == '=' ? "" : " ");
  // Objects a depth camera can pick out on a table: about 1 cm to 2 m.
  if (units == "m" && size > 5)
    throw InputError(given +
                     ", too large for an object: its coordinates look like millimetres; "
                     "use " +
                     other + "mm");
  if (units == "mm" && size < 0.005)
    throw InputError(given + ", too small for an object: its coordinates look like metres; use " +
                     other + "m");
}

}  // namespace proxseg
