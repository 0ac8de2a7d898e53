// Wavefront OBJ meshes with their MTL materials and PNG/JPEG textures, the format most object
// model sets ship (YCB, Google Scanned Objects), read into a vertex-coloured Mesh for render().
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/mesh.hpp>

#include <string>

namespace proxseg {

// Reads an OBJ mesh: `v` (x y z, optionally followed by r g b in 0..1), `vt`, `f` (triangles and
// polygons, fan-triangulated; v, v/vt, v/vt/vn and v//vn corners; negative indices count back
// from the last vertex), `mtllib`, `usemtl`, and in the MTL `newmtl`, `Kd` and `map_Kd` (a PNG or
// JPEG, its path relative to the MTL). Normals, groups, smoothing, lines and points are ignored.
// Coordinates are multiplied by scale (0.001 for millimetre models) so that the mesh is in metres.
//
// Mesh holds one colour per vertex and render() interpolates them, so a texture can only show
// through vertices: when a face samples a texture, every triangle is split at edge midpoints
// (UVs interpolated) until no edge is longer than max_edge metres, and every vertex takes the
// texture colour at its UV (bilinear, OBJ's v = 0 is the image's bottom row, UVs outside [0, 1]
// wrap). A vertex keeps one index for all the triangles that share its position, UV and material,
// and a split edge one midpoint, so the surface stays closed. A vertex without a texture takes its
// `v` line's colour, else its material's Kd, else grey 128. A mesh without textures is not split.
//
// InputError naming the file and line for malformed input (a number that is not one, an index
// out of range, an unknown material, a texture too large), an empty mesh, or a split that would
// exceed 4 million triangles (max_edge too small for the mesh, or the wrong scale); FileError
// naming the file for a missing or unreadable OBJ, MTL or used texture.
Mesh read_obj(const std::string& path, double scale = 1.0, double max_edge = 0.002);

}  // namespace proxseg
