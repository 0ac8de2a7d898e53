// ICP [paper 3.4, Algorithm 2]: the refinement of a pose by point-to-plane (or point-to-point)
// steps on the view's point grid (icp.hpp).
#include "icp.hpp"

#include "search_index.hpp"
#include "transformation_estimation.hpp"

#include <Eigen/Geometry>

namespace proxseg::detail {

// ICP refinement. The candidate's points are matched into the view's point grid (PointGrid, built
// once, when the view entered the database): every candidate point should lie on the model, while
// the view may show more of the object than the candidate does.
Eigen::Matrix4d icp(const Cloud& cand, const Cloud& view, Eigen::Matrix4d pose,
                    const RegistrationParams& p, int& iterations) {
  Eigen::Matrix4d inv = pose.inverse();  // model <- candidate
  const double r2 = p.icp_distance * p.icp_distance;
  const PointGrid& grid = view.index->points;
  std::vector<Eigen::Vector3d> src, dst, nrm;
  // Each candidate point's match of the step before (-1: none): after the first steps the
  // points move by a fraction of the spacing, and the previous match bounds the search.
  std::vector<int> previous(cand.size(), -1);
  iterations = 0;
  for (int it = 0; it < p.icp_iterations; ++it) {
    src.clear();
    dst.clear();
    nrm.clear();
    for (std::size_t i = 0; i < cand.size(); ++i) {
      const Eigen::Vector3d q = apply(inv, cand.points[i]);
      double d2 = 0;
      const double bound2 = previous[i] < 0 ? r2 : (view.points[previous[i]] - q).squaredNorm();
      const int j = bound2 < 0.25 * grid.cell * grid.cell ? nearest_within(grid, q, bound2, d2)
                                                          : nearest(grid, q, p.icp_distance, d2);
      previous[i] = j;
      if (j < 0 || d2 > r2) continue;
      src.push_back(q);
      dst.push_back(view.points[j]);
      nrm.push_back(view.normals[j]);
    }
    if (src.size() < 6) break;
    ++iterations;
    const Eigen::Matrix4d step =
        p.point_to_plane ? point_to_plane(src, dst, nrm) : kabsch(src, dst);
    inv = step * inv;
    // Converged: a step under 0.1 mm and 0.06 degrees (1e-3 rad: its rotation's trace, 1 + 2 cos
    // angle, above 1 + 2 cos 1e-3) changes no score at 5 mm.
    if (step.topLeftCorner<3, 3>().trace() > 2.999999000000083 &&
        step.topRightCorner<3, 1>().norm() < 1e-4)
      break;
  }
  return inv.inverse();
}

}  // namespace proxseg::detail
