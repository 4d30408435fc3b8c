#include "nudge/geometry/absolute_orientation.hpp"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <string>

namespace nudge::geometry {

Outcome<AbsoluteOrientation> absolute_orientation(const std::vector<Eigen::Vector3d>& from,
                                                  const std::vector<Eigen::Vector3d>& to) {
  using Result = Outcome<AbsoluteOrientation>;
  if (from.size() != to.size())
    return Result::failure("absolute orientation: " + std::to_string(from.size()) + " points but " +
                           std::to_string(to.size()) + " correspondences");
  if (from.size() < 3) return Result::failure("absolute orientation: needs at least 3 point pairs");
  for (size_t i = 0; i < from.size(); ++i)
    if (!from[i].allFinite() || !to[i].allFinite())
      return Result::failure("absolute orientation: point pair " + std::to_string(i) + " is not finite");

  const double n = static_cast<double>(from.size());
  Eigen::Vector3d mean_from = Eigen::Vector3d::Zero(), mean_to = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < from.size(); ++i) {
    mean_from += from[i] / n;
    mean_to += to[i] / n;
  }
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  double spread = 0;
  for (size_t i = 0; i < from.size(); ++i) {
    H += (from[i] - mean_from) * (to[i] - mean_to).transpose();
    spread += (from[i] - mean_from).squaredNorm();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d s = svd.singularValues();  // descending
  // Two independent directions are needed: with one (collinear points) the rotation about the line
  // is free. Relative to the spread so that the test does not depend on the unit.
  if (!(spread > 0) || s(1) < 1e-9 * std::max(s(0), 1e-300))
    return Result::failure("absolute orientation: the points lie (nearly) on one line");
  const Eigen::Matrix3d U = svd.matrixU(), V = svd.matrixV();
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((V * U.transpose()).determinant() < 0) D(2, 2) = -1;  // a reflection: flip the weakest direction
  AbsoluteOrientation out;
  out.transform.R = V * D * U.transpose();
  out.transform.t = mean_to - out.transform.R * mean_from;
  double sum = 0;
  for (size_t i = 0; i < from.size(); ++i) {
    const double e = (out.transform.apply(from[i]) - to[i]).norm();
    sum += e * e;
    out.max_residual = std::max(out.max_residual, e);
  }
  out.rms_residual = std::sqrt(sum / n);
  return Result::success(out);
}

double rotation_angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  // Through the quaternion: acos of the trace loses precision for small angles.
  return Eigen::AngleAxisd(Eigen::Quaterniond(a * b.transpose()).normalized()).angle();
}

}  // namespace nudge::geometry
