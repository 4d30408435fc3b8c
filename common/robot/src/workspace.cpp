#include "nudge/robot/workspace.hpp"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "nudge/atomic_file.hpp"
#include "nudge/yaml_file.hpp"
#include "nudge/robot/puma260.hpp"
#include "nudge/robot/safety.hpp"
#include "nudge/robot/types.hpp"

namespace nudge::robot {

namespace {

// The file's fields, in the order they are written. Angles are degrees in the file.
const char* const kFields[] = {"base_yaw_deg", "shoulder_height", "tool_length",
                               "ring_inner",   "ring_outer",      "table_margin"};

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

[[noreturn]] void fail(const std::string& path, const std::string& field, const std::string& what) {
  throw std::runtime_error(path + ": " + field + ": " + what);
}

double required_number(const YAML::Node& root, const std::string& path, const std::string& key) {
  const auto node = yaml_field(root, key);
  if (!node) fail(path, key, "missing (every workspace field is required)");
  const auto value = yaml_number(*node);
  if (!value) fail(path, key, "expected a number");
  if (!std::isfinite(*value)) fail(path, key, "must be finite");
  return *value;
}

// The file field a validate() message is about (its messages start with the struct's field name).
std::string file_field(const std::string& message) {
  if (message.rfind("base_yaw", 0) == 0) return "base_yaw_deg";
  for (const char* field : kFields) {
    if (message.rfind(field, 0) == 0) return field;
  }
  return "(workspace)";
}

}  // namespace

void validate(const Workspace& w) {
  require(std::isfinite(w.base_yaw), "base_yaw must be finite");
  require(std::isfinite(w.shoulder_height) && w.shoulder_height > 0, "shoulder_height must be positive");
  require(std::isfinite(w.tool_length) && w.tool_length >= 0 && w.tool_length < 0.5,
          "tool_length must lie in [0, 0.5) m");
  require(std::isfinite(w.ring_inner) && w.ring_inner >= 0, "ring_inner must be finite and not negative");
  require(std::isfinite(w.ring_outer) && w.ring_outer > w.ring_inner,
          "ring_outer must be finite and larger than ring_inner");
  require(std::isfinite(w.table_margin) && w.table_margin >= 0,
          "table_margin must be finite and not negative");
}

Workspace load_workspace(const std::string& path) {
  if (!std::ifstream(path).good()) throw std::runtime_error(path + ": cannot read the workspace file");
  const YAML::Node root = read_yaml_file(path, "workspace");
  if (!root.IsMap()) fail(path, "(top level)", "expected a map of workspace fields");
  const std::set<std::string> known(std::begin(kFields), std::end(kFields));
  for (const std::string& key : yaml_keys(root)) {
    if (!known.count(key)) fail(path, key, "unknown field (known: base_yaw_deg, shoulder_height, tool_length, ring_inner, ring_outer, table_margin)");
  }
  Workspace w;
  w.base_yaw = deg_to_rad(required_number(root, path, "base_yaw_deg"));
  w.shoulder_height = required_number(root, path, "shoulder_height");
  w.tool_length = required_number(root, path, "tool_length");
  w.ring_inner = required_number(root, path, "ring_inner");
  w.ring_outer = required_number(root, path, "ring_outer");
  w.table_margin = required_number(root, path, "table_margin");
  try {
    validate(w);
  } catch (const std::invalid_argument& e) {
    fail(path, file_field(e.what()), e.what());
  }
  return w;
}

void save_workspace(const Workspace& w, const std::string& path) {
  validate(w);
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out.precision(12);
  out << "%YAML:1.0\n---\n"
      << "# The arm's workspace (docs/robot.md, \"The workspace file\"); world (table) frame, metres.\n"
      << "base_yaw_deg: " << rad_to_deg(w.base_yaw) << "\n"
      << "shoulder_height: " << w.shoulder_height << "\n"
      << "tool_length: " << w.tool_length << "\n"
      << "ring_inner: " << w.ring_inner << "\n"
      << "ring_outer: " << w.ring_outer << "\n"
      << "table_margin: " << w.table_margin << "\n";
  write_file_atomically(path, out.str());
}

void apply_workspace(const Workspace& w, ArmModel* model) {
  model->tool = Eigen::Isometry3d::Identity();
  model->tool.translation() = Eigen::Vector3d(0.0, 0.0, w.tool_length);
}

void apply_workspace(const Workspace& w, SafetyConfig* safety) {
  safety->table_z = -w.shoulder_height;
  safety->table_margin = w.table_margin;
  safety->ring_inner = w.ring_inner;
  safety->ring_outer = w.ring_outer;
}

Eigen::Isometry3d BaseFrame::world_from_base() const {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(0.0, 0.0, height);
  return t;
}

Eigen::Isometry3d BaseFrame::to_base(const Eigen::Isometry3d& world_pose) const {
  return world_from_base().inverse() * world_pose;
}

Eigen::Isometry3d BaseFrame::to_world(const Eigen::Isometry3d& base_pose) const {
  return world_from_base() * base_pose;
}

Eigen::Vector3d BaseFrame::point_to_base(const Eigen::Vector3d& world_point) const {
  return world_from_base().inverse() * world_point;
}

Eigen::Vector3d BaseFrame::direction_to_base(const Eigen::Vector3d& world_direction) const {
  return world_from_base().linear().transpose() * world_direction;
}

}  // namespace nudge::robot
