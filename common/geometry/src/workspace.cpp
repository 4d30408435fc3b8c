#include "nudge/geometry/workspace.hpp"

#include <unistd.h>

#include <Eigen/Geometry>  // homogeneous()

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "nudge/atomic_file.hpp"
#include "nudge/yaml_file.hpp"

namespace nudge::geometry {

Plane plane_from_coefficients(const Eigen::Vector4d& c) {
  const Eigen::Vector3d normal = c.head<3>();
  if (!c.allFinite()) throw std::invalid_argument("table plane coefficients must be finite");
  if (!(normal.norm() > 1e-9)) throw std::invalid_argument("table plane normal (nx ny nz) must not be zero");
  Plane plane;
  plane.normal = normal.normalized();
  plane.offset = c(3) / normal.norm();
  if (plane.offset < 0) {
    plane.normal = -plane.normal;
    plane.offset = -plane.offset;
  }
  if (plane.offset < 1e-6) throw std::invalid_argument("table plane passes through the right camera");
  return plane;
}

namespace {

// A top-level sequence of `size` finite numbers, or nothing if the field is absent.
std::optional<std::vector<double>> read_numbers(const YAML::Node& root, const std::string& path,
                                                const std::string& field, size_t size) {
  const auto node = yaml_field(root, field);
  if (!node) return std::nullopt;
  const std::string expected = "must be a list of " + std::to_string(size) + " numbers";
  if (!node->IsSequence() || node->size() != size) throw std::runtime_error(path + ": field '" + field + "' " + expected);
  std::vector<double> values;
  for (const YAML::Node& item : *node) {
    const auto value = yaml_number(item);
    if (!value) throw std::runtime_error(path + ": field '" + field + "' " + expected);
    values.push_back(*value);
    if (!std::isfinite(values.back())) throw std::runtime_error(path + ": field '" + field + "' must be finite");
  }
  return values;
}

std::string numbers(std::initializer_list<double> values) {
  std::ostringstream out;
  out.precision(17);
  out << "[ ";
  const char* separator = "";
  for (double v : values) {
    out << separator << v;
    separator = ", ";
  }
  out << " ]";
  return out.str();
}

// The camera-arm calibration: both fields or neither; the rotation must be one.
std::optional<RigidTransform> read_arm_to_right(const YAML::Node& fs, const std::string& path) {
  const auto rotation = read_numbers(fs, path, "arm_to_right_rotation", 9);
  const auto translation = read_numbers(fs, path, "arm_to_right_translation", 3);
  if (!rotation && !translation) return std::nullopt;
  if (!rotation || !translation)
    throw std::runtime_error(path + ": fields 'arm_to_right_rotation' and 'arm_to_right_translation' come together");
  RigidTransform transform;
  for (int i = 0; i < 9; ++i) transform.R(i / 3, i % 3) = (*rotation)[i];
  transform.t = Eigen::Vector3d((*translation)[0], (*translation)[1], (*translation)[2]);
  const double orthogonality = (transform.R * transform.R.transpose() - Eigen::Matrix3d::Identity()).norm();
  if (orthogonality > 1e-6 || transform.R.determinant() < 0)
    throw std::runtime_error(path + ": field 'arm_to_right_rotation' is not a rotation");
  return transform;
}

}  // namespace

Workspace load_workspace(const std::string& path) {
  const YAML::Node fs = read_yaml_file(path, "stereo rig");
  Workspace workspace;
  if (const auto plane = read_numbers(fs, path, "table_plane", 4)) {
    try {
      workspace.table = plane_from_coefficients(Eigen::Vector4d((*plane)[0], (*plane)[1], (*plane)[2], (*plane)[3]));
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(path + ": field 'table_plane': " + e.what());
    }
  }
  if (const auto base = read_numbers(fs, path, "arm_base", 3))
    workspace.arm_base = Eigen::Vector3d((*base)[0], (*base)[1], (*base)[2]);
  workspace.arm_to_right = read_arm_to_right(fs, path);
  return workspace;
}

Outcome<Eigen::Vector3d> triangulate_point(const StereoRig& rig, const Eigen::Vector2d& left_pixel,
                                           const Eigen::Vector2d& right_pixel) {
  using Result = Outcome<Eigen::Vector3d>;
  const auto left = rig.left.normalise(left_pixel), right = rig.right.normalise(right_pixel);
  if (!left) return Result::failure("left: " + left.reason());
  if (!right) return Result::failure("right: " + right.reason());
  // Rays o + s d in the right camera's frame: the left one from the left camera's centre.
  const Eigen::Vector3d o_left = rig.left_centre(), d_left = rig.R * left->homogeneous();
  const Eigen::Vector3d d_right = right->homogeneous();
  const Eigen::Vector3d w = o_left;  // o_left - o_right, the right centre being the origin
  const double a = d_left.dot(d_left), b = d_left.dot(d_right), c = d_right.dot(d_right);
  const double d = d_left.dot(w), e = d_right.dot(w);
  const double denominator = a * c - b * b;
  if (!(denominator > 1e-12 * a * c)) return Result::failure("viewing rays are parallel");
  const double s_left = (b * e - c * d) / denominator, s_right = (a * e - b * d) / denominator;
  if (s_left <= 0 || s_right <= 0) return Result::failure("viewing rays meet behind a camera");
  return Result::success(0.5 * ((o_left + s_left * d_left) + s_right * d_right));
}

Outcome<Plane> table_from_corners(const StereoRig& rig, const std::vector<Eigen::Vector2d>& left,
                                  const std::vector<Eigen::Vector2d>& right) {
  if (left.size() != right.size())
    return Outcome<Plane>::failure("table corners: " + std::to_string(left.size()) + " left but " +
                                   std::to_string(right.size()) + " right");
  std::vector<Eigen::Vector3d> points;
  for (size_t i = 0; i < left.size(); ++i) {
    const auto p = triangulate_point(rig, left[i], right[i]);
    if (!p) return Outcome<Plane>::failure("table corner " + std::to_string(i) + ": " + p.reason());
    points.push_back(*p);
  }
  return fit_plane(points);
}

void save_rig(const StereoRig& rig, const Workspace& workspace, const std::string& path) {
  // The rig's own writer first (into a scratch file), then the workspace fields after it: the
  // target is replaced once, atomically, with the whole file.
  const std::string scratch = path + ".rig." + std::to_string(::getpid());
  save_rig(rig, scratch);
  std::ostringstream text;
  text << std::ifstream(scratch).rdbuf();
  std::remove(scratch.c_str());
  std::string contents = text.str();
  if (!contents.empty() && contents.back() != '\n') contents += '\n';
  if (workspace.table) {
    const Plane& t = *workspace.table;
    contents += "table_plane: " + numbers({t.normal.x(), t.normal.y(), t.normal.z(), t.offset}) + "\n";
  }
  if (workspace.arm_base) {
    const Eigen::Vector3d& b = *workspace.arm_base;
    contents += "arm_base: " + numbers({b.x(), b.y(), b.z()}) + "\n";
  }
  if (workspace.arm_to_right) {
    const Eigen::Matrix3d& R = workspace.arm_to_right->R;
    const Eigen::Vector3d& t = workspace.arm_to_right->t;
    contents += "arm_to_right_rotation: " + numbers({R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2),
                                                     R(2, 0), R(2, 1), R(2, 2)}) + "\n";
    contents += "arm_to_right_translation: " + numbers({t.x(), t.y(), t.z()}) + "\n";
  }
  write_file_atomically(path, contents);
}

}  // namespace nudge::geometry
