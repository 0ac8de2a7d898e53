// Whether a mesh's size is plausible for an object in the units it was read in: a millimetre
// mesh read as metres is a thousand times too large, and recognition would render it from a
// camera hundreds of metres away (`proxseg db render --units`, Database.render(units=)).
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/mesh.hpp>

#include <string>

namespace proxseg {

// InputError "PATH: 142.1 m across with units m, too large for an object: its coordinates look
// like millimetres; use units mm" when the mesh (in metres, after read_mesh's scale) is over
// 5 m across read as metres, or under 5 mm across read as millimetres; `flag` names the option
// in the message ("--units" for the CLI, "units=" for Python).
void check_mesh_units(const Mesh& mesh, const std::string& path, const std::string& units,
                      const std::string& flag);

}  // namespace proxseg
