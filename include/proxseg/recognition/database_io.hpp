// The model database on disk (docs/database.md): DIR/index.json, one PCD per view and one
// feature cache per view (normals and FPFH of exactly the PCD's points), so that loading does no
// feature work.
#pragma once
#include <proxseg/core/database.hpp>
#include <proxseg/core/frame.hpp>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>

namespace proxseg {

// Reads DIR/index.json, every view's PCD and feature cache. Throws InputError naming the file
// and what is wrong (missing view, stale or truncated cache, bad index field).
Database load_database(const std::string& dir);
// The database in DIR if it has an index; otherwise a new empty one with these descriptor
// parameters (nothing is written until a view is added). The descriptor is checked (InputError
// naming voxel_size, normal_radius or fpfh_radii). descriptor_given: the caller chose it, so a
// database that exists with other descriptor parameters is an InputError (they apply to a new
// one only) rather than opened with its own.
Database open_database(const std::string& dir, const DescriptorParams& descriptor,
                       bool descriptor_given = false);

// Describes one view (points in the model frame, viewpoint = sensor position in that frame,
// NaN for a full model), writes its PCD and cache, appends it and rewrites the index. Every file
// is written atomically; the index last, so an interrupted add leaves the old database intact.
const ModelView& add_view(Database& db, const std::string& object, const Frame& points,
                          const Eigen::Vector3d& viewpoint, const std::string& source);

nlohmann::json database_info(const Database& db);

}  // namespace proxseg
