// FPFH (Rusu, Blodow and Beetz, ICRA 2009) at several radii from one neighbour search per point:
// the descriptors of describe() [paper 3.4, Algorithm 2]. Private to src/recognition.
#pragma once
#include <Eigen/Core>
#include <vector>

namespace proxseg::detail {

// The FPFH of every point (33 rows per radius, radius after radius; one column per point), the
// neighbours of a point being its max_nn nearest within the radius. The values are those of
// Open3D's ComputeFPFHFeature with KDTreeSearchParamHybrid(radius, max_nn), to the last bit,
// which the database's stored views were described with; Open3D searches the max_nn nearest
// twice per radius and cuts the list at the radius, so one search serves every radius here.
Eigen::MatrixXd fpfh_features(const std::vector<Eigen::Vector3d>& points,
                              const std::vector<Eigen::Vector3d>& normals,
                              const std::vector<double>& radii, int max_nn);

}  // namespace proxseg::detail
