#pragma once
// The arm service's logic without LCM I/O: turns arm_command_t requests into checked joint
// motions, executes them on a backend as time passes, and reports arm_state_t.
//
// Time: the controller has no clock of its own. advance_to() moves it to a time given by the
// service (wall, simulated or log time, see main.cpp); it steps the backend in publication
// periods, so the same inputs at the same times give the same states, sample for sample.
//
// Safety, whatever the backend: a command is planned and checked completely before anything
// moves (robot::plan_command: IK reachability, joint limits, table clearance, the workspace ring,
// every joint-space segment sampled densely); otherwise it is refused with the reason and the arm
// keeps still.
// One command runs at a time; while it runs, anything but COMMAND_STOP is refused ("busy").
#include <Eigen/Geometry>

#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "backends.hpp"
#include "nudge/bus/pose_convert.hpp"
#include "nudge/arm_command_t.hpp"
#include "nudge/arm_state_t.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/robot/command_planner.hpp"

namespace nudge::arm {

struct ControllerConfig {
  robot::PlannerConfig planner;  // model, safety, base frame, nudge/grasp/home defaults, speed
  int64_t period_utime = 10000;  // ARM_STATE period and backend step (100 Hz)
  // States more than this far behind a clock jump are not published (the backend still steps
  // through them); < 0: publish every period (log replay, where every sample is wanted).
  int64_t max_catch_up_utime = 1000000;
  double supervisor_timeout = 1.5;  // seconds without a supervisor heartbeat before stopping
  bool require_supervisor = false;  // refuse motions until a supervisor heartbeat arrives
};

// Throws std::invalid_argument naming the field.
void validate(const ControllerConfig& config);

class ArmController {
 public:
  using Publish = std::function<void(const arm_state_t&)>;

  ArmController(ControllerConfig config, Backend backend);

  // Moves the clock forward to `utime` (earlier times are ignored), stepping the backend and the
  // running motion one period at a time, and calls `publish` at every period boundary crossed.
  // The first call only sets the clock.
  void advance_to(int64_t utime, const Publish& publish);

  // Like advance_to, with the supervisor watchdog on the same clock: if the heartbeat deadline
  // falls before `utime`, the arm stops exactly at the deadline.
  void advance_with_watchdog(int64_t utime, const Publish& publish);

  // Plans, checks and starts a command at the current clock; returns the state to publish at
  // once (MOTION_MOVING when accepted, MOTION_REFUSED with the reason when not, ...).
  arm_state_t handle(const arm_command_t& command);

  // HEARTBEAT messages: those of the supervisor feed the watchdog (`utime` on the watchdog's
  // clock). A supervisor announcing STATE_STOPPING counts as lost at once. Returns true when it
  // stopped the arm (publish state() then).
  bool on_heartbeat(const heartbeat_t& heartbeat, int64_t utime);
  // Stops the arm when the supervisor's heartbeat has been missing too long. Returns true when it
  // stopped the arm just now.
  bool check_supervisor(int64_t utime);
  // When the watchdog will fire if no heartbeat arrives (none while not armed).
  std::optional<int64_t> supervisor_deadline() const;

  // The fingers' opening as a sensor measured it (the sim backend: the MuJoCo world's fingers,
  // from SIM_STATE); negative: unknown. Reported in ARM_STATE.gripper_measured.
  void set_measured_gripper(double opening) { measured_gripper_ = opening < 0 ? -1.0 : opening; }

  arm_state_t state() const;
  int64_t clock() const { return clock_; }
  bool busy() const { return !steps_.empty(); }
  // Refused commands with malformed content (wrong joint count, bad numbers, unknown code):
  // counted as input errors by the service.
  int64_t malformed_commands() const { return malformed_commands_; }
  // One line for the service's heartbeat status.
  std::string describe() const;

 private:
  using Step = robot::MotionStep;

  arm_state_t refuse(const arm_command_t& command, const std::string& reason, bool malformed);
  void step_backend_to(int64_t utime);
  void update_motion();
  bool start_step(const Step& step);
  void abort(const std::string& reason);
  void lose_supervisor(const std::string& reason);

  ControllerConfig config_;
  Backend backend_;
  bool started_ = false;
  int64_t clock_ = 0, backend_clock_ = 0, next_publish_ = 0;

  std::deque<Step> steps_;
  bool step_started_ = false;
  std::string running_;  // what the running command is, for describe()

  int8_t motion_ = arm_state_t::MOTION_IDLE;
  int64_t command_seq_ = -1;
  std::string last_error_;
  int64_t malformed_commands_ = 0;
  double measured_gripper_ = -1;

  bool supervisor_seen_ = false;
  int64_t supervisor_last_ = 0;
  std::string supervisor_problem_;  // non-empty while the supervisor is lost
};

}  // namespace nudge::arm
