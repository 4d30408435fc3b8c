#pragma once
// The command-line side of the workspace: --workspace FILE, and per-field flags that override the
// file (the flags services had before the file, kept working). Every service that needs the
// workspace resolves it the same way: the code's defaults (robot::Workspace{}), then the file if
// given, then each override flag given on the command line.
#include <string>
#include <vector>

#include "nudge/flags.hpp"
#include "nudge/robot/workspace.hpp"

namespace nudge::robot {

class WorkspaceFlags {
 public:
  // The override flags there are: "base-height", "base-yaw-deg", "tool-length", "ring-inner",
  // "ring-outer", "table-margin". `help_prefix` starts their help ("CANDIDATES: ").
  // Registers --workspace and the named overrides on `flags`, which must outlive this object.
  WorkspaceFlags(Flags& flags, const std::vector<std::string>& overrides, const std::string& help_prefix = "");
  WorkspaceFlags(const WorkspaceFlags&) = delete;
  WorkspaceFlags& operator=(const WorkspaceFlags&) = delete;

  // After flags.parse(): the workspace. Throws FlagError naming the file and field, or the flag.
  Workspace resolve() const;
  // The --workspace file ("" when the code's defaults were used).
  const std::string& file() const { return file_; }

 private:
  Flags& flags_;
  std::string file_;
  Workspace values_;           // what the override flags were given
  double base_yaw_deg_ = 0.0;  // --base-yaw-deg, degrees
};

}  // namespace nudge::robot
