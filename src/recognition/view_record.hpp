// The bytes of a stored view (docs/database.md, "Records"): three records per view, each ending
// in its checksum (util/checksum.hpp), so that a damaged one is told and confined to its view:
//   summary  what opening reads: viewpoint, the whole view's signature, its parts' sketches;
//   parts    the parts' signatures, read when the shortlist needs them;
//   body     points, normals, FPFH and colours, read when the shortlist picks the view.
// Floats little-endian, as the machines proxseg runs on (the format is checked at open).
#pragma once
#include <proxseg/core/database.hpp>

#include <string>
#include <vector>

namespace proxseg::detail {

struct ViewSummary {
  Eigen::Vector3d viewpoint = Eigen::Vector3d::Zero();
  Signature signature;
  SketchSet part_sketches;
};

std::string encode_summary(const ViewSummary& s);
std::string encode_parts(const std::vector<Signature>& parts);
// The cloud's points, normals and features as floats, its colours as bytes.
std::string encode_body(const Cloud& c);

// Each decoder throws InputError(where + ": " + what is damaged) for a record that is not whole:
// a checksum that does not match, sizes that disagree, non-finite values.
ViewSummary decode_summary(const std::string& where, const std::string& bytes);
std::vector<Signature> decode_parts(const std::string& where, const std::string& bytes);
// restore()s the described cloud: `points` and `dims` (33 x FPFH radii) are what the view's row
// and the database's descriptor say it holds.
Cloud decode_body(const std::string& where, const std::string& bytes, std::size_t points,
                  std::size_t dims, const Eigen::Vector3d& viewpoint);

}  // namespace proxseg::detail
