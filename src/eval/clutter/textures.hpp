// The textures of the cluttered scene generator (docs/clutter.md, "box textures", "cylinder
// textures", "table"): procedural colours of boxes and cylinders per vertex (plain, stripes,
// checks, blotches, printed labels, bands, lids) and of the table top per pixel (wood, checked
// cloth, plain), each drawn from the scene's random stream. Private to the library.
#pragma once
#include <proxseg/core/render.hpp>

#include <Eigen/Core>
#include <functional>
#include <string>

#include "eval/clutter/random.hpp"

namespace proxseg::clutter {

using Col = Eigen::Vector3d;  // 0..255 per channel

// Box (its extents, centred on the origin): plain, stripes, checker, blotches or label; name
// takes the texture's name.
ColourFn box_texture(Rng& r, const Vec3& size, std::string& name);

// Cylinder (axis z, -h/2..h/2): plain, bands, vertical stripes, blotches or a label band; the
// caps may be a lid of another colour.
ColourFn cylinder_texture(Rng& r, double radius, double height, std::string& name);

// Table colour at a point of the table plane, box-filtered over w metres (the pixel's footprint):
// the table is textured per pixel after rendering, so that fine patterns do not alias.
using TableFn = std::function<Col(const Vec2& p, double w)>;

// Table top of a kind: "wood" (planks, rings perturbed by noise), "cloth" (gingham) or plain.
TableFn table_texture(Rng& r, const std::string& kind);

}  // namespace proxseg::clutter
