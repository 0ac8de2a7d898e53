// The capture of a cluttered scene (docs/clutter.md, "camera", "sensor", "validity"): the
// camera drawn around the layout until a quick render shows every object, then the full render
// with the table textured per pixel, the sensor's colour noise and the visible points per
// object. Private to the library.
#pragma once
#include <proxseg/core/mesh.hpp>
#include <proxseg/eval/clutter.hpp>

#include <vector>

#include "eval/clutter/random.hpp"
#include "eval/clutter/textures.hpp"

namespace proxseg::clutter {

// The stage of a scene, drawn before its objects: the table (centred on the world origin, its
// edges along x and y) and the light (fixed in the world).
struct Stage {
  double table_w = 0, table_d = 0;  // extents along x and y, metres
  TableFn table_colour;
  Vec3 light = Vec3::UnitZ();  // unit direction towards the light
  double ambient = 0, exposure = 0;
};

// Draws up to 6 cameras (elevation, azimuth, look-at point, then the distance: uniform between
// the nearest at which every corner is in the image with a 12 px margin, and max_distance) and
// stops at the first under which a quarter-resolution render of the objects' meshes shows every
// object with 1.2 x min_visible_points (scaled). out takes the last camera drawn (eye, target,
// elevation, azimuth); false if none showed every object. out.objects must be filled. With
// p_front the azimuth stays within 15 degrees of view_az.
bool choose_camera(Rng& r, const ClutterParams& P, const std::vector<Mesh>& meshes,
                   const std::vector<Vec3>& corners, const Vec2& area_centre, double view_az,
                   ClutterScene& out);

// The full render from out's camera: the objects' meshes (the table is appended to them), the
// table coloured per pixel, colour noise; sets out.render, out.frame and every object's
// visible_points. False if some object shows fewer than min_visible_points.
bool capture(Rng& r, const ClutterParams& P, const Stage& stage, std::vector<Mesh>& meshes,
             ClutterScene& out);

}  // namespace proxseg::clutter
