#include "nudge/robot/workspace_flags.hpp"

#include <stdexcept>

#include "nudge/robot/types.hpp"

namespace nudge::robot {

WorkspaceFlags::WorkspaceFlags(Flags& flags, const std::vector<std::string>& overrides, const std::string& help_prefix)
    : flags_(flags), base_yaw_deg_(rad_to_deg(values_.base_yaw)) {
  flags.add_string("workspace", &file_,
                   "workspace file (docs/robot.md; config/workspace.yaml; default: the same values in code)");
  const std::string overriding = " (overrides the workspace file)";
  for (const std::string& name : overrides) {
    if (name == "base-height") {
      flags.add_double(name, &values_.shoulder_height, help_prefix + "shoulder (base frame origin) above the table top, m" + overriding);
    } else if (name == "base-yaw-deg") {
      flags.add_double(name, &base_yaw_deg_, help_prefix + "base x axis about the world z axis, degrees" + overriding);
    } else if (name == "tool-length") {
      flags.add_double(name, &values_.tool_length, help_prefix + "tool point (pad centre / gripper centre) along the flange z axis, m" + overriding);
    } else if (name == "ring-inner") {
      flags.add_double(name, &values_.ring_inner, help_prefix + "workspace ring: inner radius of the tool point, m" + overriding);
    } else if (name == "ring-outer") {
      flags.add_double(name, &values_.ring_outer, help_prefix + "workspace ring: outer radius of the tool point, m" + overriding);
    } else if (name == "table-margin") {
      flags.add_double(name, &values_.table_margin, help_prefix + "tool, wrist and elbow stay this far above the table, m" + overriding);
    } else {
      throw std::invalid_argument("no workspace override flag --" + name);
    }
  }
}

Workspace WorkspaceFlags::resolve() const {
  Workspace w;
  if (!file_.empty()) {
    try {
      w = load_workspace(file_);
    } catch (const std::runtime_error& e) {
      throw FlagError(std::string("--workspace ") + e.what());
    }
  }
  if (flags_.given("base-height")) w.shoulder_height = values_.shoulder_height;
  if (flags_.given("base-yaw-deg")) w.base_yaw = deg_to_rad(base_yaw_deg_);
  if (flags_.given("tool-length")) w.tool_length = values_.tool_length;
  if (flags_.given("ring-inner")) w.ring_inner = values_.ring_inner;
  if (flags_.given("ring-outer")) w.ring_outer = values_.ring_outer;
  if (flags_.given("table-margin")) w.table_margin = values_.table_margin;
  try {
    validate(w);
  } catch (const std::invalid_argument& e) {
    throw FlagError(std::string("workspace") + (file_.empty() ? "" : " " + file_) + " with the flags given: " + e.what());
  }
  return w;
}

}  // namespace nudge::robot
