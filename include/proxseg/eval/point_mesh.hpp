// Triangle meshes from bare point samples of an object's surface (the YCB-Video models ship only
// as points.xyz: no normals, no colour), so that render() can draw them into depth views.
//
// The samples are sparse and very uneven (curved parts and edges dense, flat faces with gaps of
// 2-3 cm), walls are thin (a bowl, a mug), and parts are close together (clamp jaws, scissor
// loops). Poisson reconstruction closes the open bowl and mug and punches holes where its
// density trim meets the gaps; ball pivoting leaves holes and needs consistently oriented
// normals, which thin walls do not give; a ball closing either leaks through the gaps or fills
// the concavities. What works on all 21 models is a surfel layer: every point owns its Voronoi
// cell among its neighbours, restricted to its tangent plane, so the cells tile the sampled
// surface and bridge the gaps however large, but stop at rims, sharp edges and openings, where
// no neighbour lies in the plane. The cells are thickened into a thin layer on a voxel grid, the
// space reachable from outside without crossing the layer is flood-filled, the boundary of the
// rest is extracted (surface nets) and moved back onto the points. Closed objects come out
// solid, thin walls as thin closed shells, openings open.
//
// docs/point_mesh.md has the measurements that chose this (and the parameters below).
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>
#include <proxseg/core/mesh.hpp>

#include <Eigen/Core>
#include <vector>

namespace proxseg {

struct PointMeshParams {
  // Grid spacing, metres. The points lie within about half of it from the surface; the triangle
  // count grows as 1 / voxel^2, time and memory as 1 / voxel^3.
  double voxel = 0.0015;
  // Half the thickness of the surfel layer, in voxels. At least 0.5 so that no path between
  // neighbouring grid nodes crosses the layer (the flood fill cannot leak through a cell).
  double half_thickness = 0.75;
  // Move the extracted surface back by the half thickness (along its normals), so that it
  // passes through the points instead of half_thickness * voxel outside them. Thin walls then
  // become two coincident sheets, which render as one.
  bool shrink = true;

  // Nearest neighbours whose covariance gives a point's normal (its tangent plane). Each is
  // weighted by the area it stands for (squared distance to its 6th neighbour), so that the
  // dense samples along an edge do not tilt the plane of a sparse face next to it.
  int normal_neighbours = 24;
  // Nearest neighbours whose bisector planes cut a point's cell (its Voronoi cell). Must reach
  // across the widest gaps of the sparse faces, or the cells leave cracks there.
  int cell_neighbours = 48;
  // A cell's largest radius, metres (a point with no neighbour in some direction of its plane).
  double max_cell_radius = 0.025;
  // Surface variation (smallest eigenvalue / sum of the covariance's eigenvalues) above which a
  // point is taken to lie on an edge or corner: its plane is unreliable, so its cell is capped
  // at the distance to its 3rd neighbour (otherwise it sticks out of the object as a fin).
  double edge_variation = 0.02;
  // Neighbours within this angle of a point's tangent plane, degrees, support its cell: the cell
  // is cut to their convex hull (in the plane) grown by support_margin + support_spacing times
  // the point's spacing (distance to its 6th neighbour). This stops cells at rims, sharp edges
  // and openings, where the plane has no samples beyond the point.
  double support_angle_deg = 20;
  double support_margin = 0.0005;
  double support_spacing = 0.6;
  // Cells are scaled about their point by this, so that neighbouring cells (in slightly
  // different planes) overlap instead of leaving cracks.
  double cell_growth = 1.1;

  Rgb colour{128, 128, 128};  // every vertex's colour: geometry only, neutral grey
};

// A closed-looking triangle mesh through the points (metres), in their frame, triangles wound
// outwards, every vertex params.colour, label 0. Deterministic: single-threaded, the same
// points and parameters give the same mesh bit for bit, whatever the thread settings. InputError
// for fewer than 4 points or
// a non-finite coordinate, for parameters out of range or a grid of more than 100 million nodes
// (raise voxel).
Mesh mesh_from_points(const std::vector<Eigen::Vector3d>& points,
                      const PointMeshParams& params = {});

}  // namespace proxseg
