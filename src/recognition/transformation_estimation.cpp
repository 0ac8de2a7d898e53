// Transformation estimation [paper 3.4, Algorithm 2]: point-to-point (Kabsch/Umeyama) and
// linearised point-to-plane least-squares fits (transformation_estimation.hpp).
#include "transformation_estimation.hpp"

#include <Eigen/Geometry>

namespace proxseg::detail {

Eigen::Matrix4d kabsch(const std::vector<Eigen::Vector3d>& src,
                       const std::vector<Eigen::Vector3d>& dst) {
  Eigen::Matrix3Xd a(3, src.size()), b(3, dst.size());
  for (std::size_t i = 0; i < src.size(); ++i) {
    a.col(i) = src[i];
    b.col(i) = dst[i];
  }
  return Eigen::umeyama(a, b, false);
}

Eigen::Matrix4d point_to_plane(const std::vector<Eigen::Vector3d>& src,
                               const std::vector<Eigen::Vector3d>& dst,
                               const std::vector<Eigen::Vector3d>& normal) {
  Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> atb = Eigen::Matrix<double, 6, 1>::Zero();
  for (std::size_t i = 0; i < src.size(); ++i) {
    Eigen::Matrix<double, 6, 1> row;
    row << src[i].cross(normal[i]), normal[i];
    ata += row * row.transpose();
    atb += row * (dst[i] - src[i]).dot(normal[i]);
  }
  const Eigen::Matrix<double, 6, 1> x = ata.ldlt().solve(atb);
  Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
  t.topLeftCorner<3, 3>() = (Eigen::AngleAxisd(x(2), Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(x(1), Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(x(0), Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  t.topRightCorner<3, 1>() = x.tail<3>();
  return t;
}

}  // namespace proxseg::detail
