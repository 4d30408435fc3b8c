// arm: the PUMA 260 arm service. Takes arm_command_t requests on ARM_COMMAND (stop, move joints,
// move to pose, nudge, grasp, open/close the gripper, rotate the wrist, place, home), checks every
// one whatever the backend, executes the accepted ones as trapezoidal or waypoint trajectories and
// publishes arm_state_t on ARM_STATE at --rate (joints, gripper, the tool point in the WORLD frame
// of docs/sim.md, motion status, last command, last error). Stops when told to, and when the
// supervisor's heartbeat, once heard, goes missing. See docs/robot.md, "The arm service".
//
// Clocks (--clock): trajectories run on one of
//   wall  the host's clock: live runs with a real (or fake) arm;
//   sim   the utime of SIM_STATE: the MuJoCo world steps in simulated time, maybe faster or slower
//         than real time, and the arm must move by the world's time or pushes would go at the
//         wrong speed (the watchdog stays on the wall clock: the supervisor beats in real time);
//   log   message time: the utime field of every ARM_COMMAND and HEARTBEAT (not SIM_STATE's: its
//         simulated time does not mix with the senders' wall clocks); the default for a file://
//         input. The service is then a pure function from
//         log to log, its output the same on every run, however fast the log is read. (LCM's file
//         provider at speed=0 stamps events with the time it reads them, not with the log's
//         timestamps, so those cannot serve.)
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "arm_controller.hpp"
#include "backends.hpp"
#include "nudge/arm_command_t.hpp"
#include "nudge/arm_state_t.hpp"
#include "nudge/bus/channels.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/bus_clock.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/log.hpp"
#include "nudge/robot/kinematics.hpp"
#include "nudge/robot/motions.hpp"
#include "nudge/robot/safety.hpp"
#include "nudge/robot/workspace_flags.hpp"
#include "nudge/sim_state_t.hpp"

using namespace nudge;

namespace {

BusClock parse_clock(const std::string& name, bool input_is_log) {
  try {
    return BusClock(parse_clock_source(name, input_is_log));
  } catch (const std::invalid_argument& e) {
    throw FlagError(std::string("--clock: ") + e.what());
  }
}

robot::JointVector initial_joints(const std::vector<double>& degrees, const robot::PlannerConfig& planner) {
  if (!degrees.empty()) {
    const robot::JointVector q = robot::joints_from_degrees(degrees[0], degrees[1], degrees[2],
                                                            degrees[3], degrees[4], degrees[5]);
    const robot::CheckResult limits = robot::check_joint_limits(planner.model, q);
    if (!limits.ok()) throw FlagError("--initial-joints: " + limits.reason);
    return q;
  }
  robot::SafetyConfig safety = planner.safety;
  safety.table_z = planner.base.table_z();
  const robot::IkResult home =
      robot::home_configuration(planner.model, safety, planner.home_radius, planner.home_height);
  if (!home.ok()) throw FlagError("no home pose to start from: " + home.reason);
  return home.q;
}

}  // namespace

int main(int argc, char** argv) {
  return bus::guarded_main("arm", [&] {
    bus::Service service("arm", "PUMA 260 arm: checked moves, nudges and grasps (thesis ch. 6-7, App. B).");
    arm::ControllerConfig config;
    std::string backend_name = "sim", clock_name = "auto";
    std::string command_channel = bus::channel::ARM_COMMAND, state_channel = bus::channel::ARM_STATE, sim_channel = bus::channel::SIM_STATE;
    robot::PlannerConfig& planner = config.planner;
    double rate = 100;
    double gripper_speed = 0.05, max_catch_up = 1.0;
    std::vector<double> initial_deg;
    auto& f = service.flags();
    f.add_string("backend", &backend_name, "sim (kinematic arm the world follows) or fake (robot::FakeDriver)");
    f.add_string("clock", &clock_name, "auto (log for file:// inputs, else wall), wall, sim (SIM_STATE utime) or log (utime of commands and heartbeats)");
    f.add_string("command-channel", &command_channel, "arm_command_t input");
    f.add_string("state-channel", &state_channel, "arm_state_t output");
    f.add_string("sim-channel", &sim_channel, "sim_state_t input for --clock sim and the sim backend's measured finger opening");
    f.add_double("rate", &rate, "ARM_STATE messages per second of the clock");
    f.add_double("max-catch-up", &max_catch_up, "after a clock jump publish at most this many seconds of states (wall, sim)");
    const robot::WorkspaceFlags workspace_flags(
        f, {"base-height", "base-yaw-deg", "tool-length", "table-margin", "ring-inner", "ring-outer"});
    f.add_doubles("initial-joints", &initial_deg, 6, "joints at start, degrees (default: the home pose)");
    f.add_double("speed-scale", &planner.speed_scale, "fraction of the joint speed limits for commands that give 0");
    f.add_double("home-radius", &planner.home_radius, "COMMAND_HOME: tool point from the base axis, m");
    f.add_double("home-height", &planner.home_height, "COMMAND_HOME: tool point above the table, m");
    f.add_double("approach-height", &planner.nudge.approach_height, "nudge P0: tool above the table, m (default for 0)");
    f.add_double("push-height", &planner.nudge.push_height, "nudge P1/P2: tool above the table, m (default for 0)");
    f.add_double("start-distance", &planner.nudge.start_distance, "nudge Dmax: P1 before the target axis, m (default for 0)");
    f.add_double("stop-distance", &planner.nudge.stop_distance, "nudge Dmin: P2 before the target axis, m (default for 0)");
    double nudge_tilt_deg = robot::rad_to_deg(planner.nudge.tool_tilt);
    f.add_double("nudge-tilt-deg", &nudge_tilt_deg, "nudge: lean of the tool when the straight-down tool's wrist would strike the object, deg (0: never lean)");
    f.add_double("object-height", &planner.nudge.object_height, "nudge: the tallest object the forearm and wrist must clear, m (0: no check)");
    f.add_double("object-radius", &planner.nudge.object_radius, "nudge: that object's radius, m");
    f.add_double("grasp-approach-height", &planner.grasp.approach_height, "grasp/place: tool above the table before descending, m");
    f.add_double("lift-height", &planner.grasp.lift_height, "grasp: tool above the table after lifting, m");
    f.add_double("gripper-speed", &gripper_speed, "sim backend: gripper finger speed, m/s");
    f.add_double("supervisor-timeout", &config.supervisor_timeout, "stop when a supervisor heartbeat, once heard, is missing this long, s");
    f.add_bool("require-supervisor", &config.require_supervisor, "refuse motions until a supervisor heartbeat arrives");
    if (!service.parse(argc, argv)) return 0;

    planner.nudge.tool_tilt = robot::deg_to_rad(nudge_tilt_deg);
    BusClock clock = parse_clock(clock_name, service.input_is_log());
    if (!(rate > 0 && rate <= 1000)) throw FlagError("--rate must lie in (0, 1000]");
    if (!(max_catch_up >= 0)) throw FlagError("--max-catch-up must not be negative");
    const robot::Workspace workspace = workspace_flags.resolve();
    robot::apply_workspace(workspace, &planner.model);
    robot::apply_workspace(workspace, &planner.safety);
    planner.base = robot::BaseFrame::of(workspace);
    config.period_utime = std::llround(1e6 / rate);
    // A log replay wants every sample; live, a long jump (a paused world) is not worth a flood.
    config.max_catch_up_utime = clock.source() == ClockSource::Log ? -1 : std::llround(max_catch_up * 1e6);
    std::unique_ptr<arm::ArmController> controller;
    try {
      arm::validate(config);
      arm::Backend backend = arm::make_backend(backend_name, planner.model,
                                               initial_joints(initial_deg, planner), gripper_speed);
      controller = std::make_unique<arm::ArmController>(config, std::move(backend));
    } catch (const std::invalid_argument& e) {
      throw FlagError(e.what());
    }

    service.start();
    const arm::ArmController::Publish publish = [&](const arm_state_t& state) {
      service.publish(state_channel, state);
    };
    int64_t malformed_counted = 0;
    auto after_event = [&] {
      // Commands refused for malformed content count as input errors in the heartbeat.
      service.counters().errors += controller->malformed_commands() - malformed_counted;
      malformed_counted = controller->malformed_commands();
      service.set_status(controller->describe());
    };

    // A message moves the clock (BusClock: wall time, or its utime on --clock log) before it is
    // acted on. With the supervisor's deadlines on message time (a log) the watchdog moves with it.
    auto follow = [&](int64_t utime, Stamp stamp) {
      const std::optional<int64_t> now = clock.on_message(utime, stamp);
      if (!now) return;
      if (clock.deadlines_on_message_time()) {
        controller->advance_with_watchdog(*now, publish);
      } else {
        controller->advance_to(*now, publish);
      }
    };
    service.subscriptions().subscribe<arm_command_t>(command_channel, [&](const arm_command_t& command, const std::string&) {
      follow(command.utime, Stamp::Sender);
      const arm_state_t response = controller->handle(command);
      publish(response);
      if (response.motion == arm_state_t::MOTION_REFUSED) {
        log::warn() << "refused command " << command.seq << ": " << response.last_error;
      } else {
        log::info() << "command " << command.seq << ": " << controller->describe();
      }
      after_event();
    });
    service.subscriptions().subscribe<heartbeat_t>(bus::channel::HEARTBEAT, [&](const heartbeat_t& heartbeat, const std::string&) {
      follow(heartbeat.utime, Stamp::Sender);
      if (controller->on_heartbeat(heartbeat, clock.deadline_time())) {
        publish(controller->state());
        log::warn() << controller->describe();
      }
      after_event();
    });
    // The sim backend's finger sensor is the MuJoCo world: its SIM_STATE says how far the fingers
    // really closed (on an object, or on nothing), which a drop check needs.
    const bool measure_in_world = backend_name == "sim";
    if (clock.source() == ClockSource::Sim || measure_in_world) {
      service.subscriptions().subscribe<sim_state_t>(sim_channel, [&, measure_in_world](const sim_state_t& sim, const std::string&) {
        if (measure_in_world && std::isfinite(sim.gripper)) controller->set_measured_gripper(sim.gripper);
        if (clock.source() == ClockSource::Sim) follow(sim.utime, Stamp::Simulated);
      });
    }
    if (const std::optional<int64_t> now = clock.on_timer()) controller->advance_to(*now, publish);
    if (clock.source() != ClockSource::Log) publish(controller->state());  // the world places its pusher at once
    log::info() << "backend " << backend_name << ", clock " << clock_source_name(clock.source()) << ", " << command_channel << " -> "
                << state_channel << " at " << rate << " Hz; base " << planner.base.height << " m above the table, yaw "
                << robot::rad_to_deg(planner.base.yaw) << " deg, tool " << workspace.tool_length << " m, ring "
                << workspace.ring_inner << "-" << workspace.ring_outer << " m"
                << (workspace_flags.file().empty() ? "" : " (" + workspace_flags.file() + ")");

    const int wait_ms = std::max(1, static_cast<int>(500.0 / rate));  // two looks per period
    return service.run([&] {
      if (clock.deadlines_on_message_time()) return wait_ms;  // time moves only with the log
      if (controller->check_supervisor(clock.deadline_time())) {
        publish(controller->state());
        log::warn() << controller->describe();
      }
      if (const std::optional<int64_t> now = clock.on_timer()) controller->advance_to(*now, publish);
      after_event();
      return wait_ms;
    }, wait_ms);
  });
}
