#pragma once
// Small fixed-size linear-algebra types used everywhere (Eigen).
#include <Eigen/Dense>
#include <span>
#include <vector>

namespace ibrod {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;  ///< a triad: columns are D1, D2, D3

/// Rotation matrix for the rotation vector theta (angle |theta| about theta/|theta|), Rodrigues'
/// formula. Exact orthogonal to round-off for any angle; the identity for theta = 0.
inline Mat3 rotation(const Vec3& theta) {
  const double a = theta.norm();
  if (a < 1e-300) return Mat3::Identity();
  return Eigen::AngleAxisd(a, theta / a).toRotationMatrix();
}

}  // namespace ibrod
