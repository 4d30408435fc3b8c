// world: the simulated lab (MuJoCo physics of the table, the objects and the arm's pusher pad).
// Publishes SIM_STATE at --rate in simulated time, answers SIM_TRUTH_REQUEST with SIM_TRUTH
// (state + both cameras' object masks), and puts the pusher (or, with --tool gripper, the
// gripper, its opening from ARM_STATE.gripper; --tool auto: the gripper from a COMMAND_GRASP on,
// the pad from a COMMAND_NUDGE on, and from a COMMAND_HOME with the fingers open) at the arm's tool
// point from ARM_STATE. All logic
// runs on simulated time; see docs/sim.md, "The world service".
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "nudge/arm_command_t.hpp"
#include "nudge/arm_state_t.hpp"
#include "nudge/bus/arm_convert.hpp"
#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/bus/pose_convert.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/bus_clock.hpp"
#include "nudge/log.hpp"
#include "nudge/robot/workspace_flags.hpp"
#include "nudge/sim/mjcf.hpp"
#include "nudge/sim/state_sync.hpp"
#include "nudge/sim/world.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/sim_truth_request_t.hpp"
#include "nudge/sim_truth_t.hpp"

using namespace nudge;

namespace {


// The world's physics, its pusher (driven by the arm) and what it publishes, on simulated time.
class Simulation {
 public:
  Simulation(bus::Service& service, const sim::Scene& scene, double rate, bool gripper, double tool_length)
      : service_(service), world_(scene), gripper_(gripper) {
    const double period = 1.0 / rate;
    steps_per_state_ = std::max<int64_t>(1, std::llround(period / world_.timestep()));
    if (std::abs(steps_per_state_ * world_.timestep() - period) > 1e-9)
      log::warn() << "--rate " << rate << " Hz is not a whole number of " << world_.timestep() * 1e3
                  << " ms physics steps: publishing every " << steps_per_state_ << " steps ("
                  << 1.0 / (steps_per_state_ * world_.timestep()) << " Hz)";
    world_.park_pusher();
    // With the PUMA 260 in the scene the tools ride on its simulated flange; ARM_STATE's joints
    // drive it, its tool pose then only checks out.
    if (world_.has_arm()) {
      world_.mount_tools_on_arm(tool_length);
      if (gripper_) world_.set_gripper_opening(sim::gripper_geometry().max_opening);
    }
  }

  double time() const { return static_cast<double>(step_) * world_.timestep(); }
  double timestep() const { return world_.timestep(); }
  int64_t utime() const { return std::llround(time() * 1e6); }

  // One physics step with the pusher where the arm last put it; publishes SIM_STATE on the
  // rate's boundaries.
  void step() {
    world_.step();
    ++step_;
    if (step_ % steps_per_state_ == 0) service_.publish(bus::channel::SIM_STATE, state_message());
  }
  // Simulated time never goes past this (--duration).
  void set_end_time(double seconds) { end_time_ = seconds; }
  bool finished() const { return time() + 0.5 * world_.timestep() >= end_time_; }
  // Steps until simulated time reaches `seconds` (never backwards, never past the end time).
  void advance_to(double seconds) {
    seconds = std::min(seconds, end_time_);
    while (time() + 0.5 * world_.timestep() < seconds && !service_.stop_requested()) step();
  }
  // Steps up to the next SIM_STATE boundary (at most that many steps).
  void advance_to_next_state() {
    do step();
    while (step_ % steps_per_state_ != 0 && !finished());
  }

  // The arm's contract: the tool point is the pad centre (the gripper's centre with --tool
  // gripper); the pad faces the horizontal direction of the tool's x axis (the previous yaw is kept
  // while that axis points straight up or down); the gripper's fingers close across it, towards
  // the opening ARM_STATE.gripper.
  void on_arm_state(const arm_state_t& msg) {
    const bus::ArmState arm = bus::from_message(msg);  // throws naming a bad field
    const Eigen::Vector3d p = arm.tool_in_world.translation();
    const Eigen::Quaterniond q(arm.tool_in_world.linear());
    if (world_.has_arm()) {  // the simulated PUMA's servos follow the arm's joints
      std::array<double, 6> joints;
      std::copy(arm.joints.begin(), arm.joints.end(), joints.begin());
      world_.set_arm_targets(joints);
    }
    if (world_.tools_on_arm()) {  // the tool is where the simulated arm puts it
      if (gripper_) world_.set_gripper_opening(msg.gripper);
      arm_ = msg;
      return;
    }
    if (const auto yaw = sim::pad_yaw_from_tool(q)) pusher_yaw_ = *yaw;
    if (gripper_)
      world_.set_end_effector(p, pusher_yaw_, msg.gripper);
    else
      world_.set_pusher(p, pusher_yaw_);
    arm_ = msg;
  }

  void on_truth_request(bool with_masks) {
    // After a step MuJoCo's body positions are those from before its integration: restoring the
    // state recomputes them from the poses the state message reports (and changes nothing else).
    world_.set_state(world_.state());
    sim_truth_t truth;
    truth.state = state_message();
    truth.utime = truth.state.utime;
    for (int c = 0; c < 2; ++c) {
      image_t& mask = c == 0 ? truth.mask_left : truth.mask_right;
      const char* camera = c == 0 ? "left" : "right";
      if (with_masks) {
        mask = bus::to_message(world_.render_mask(c), image_t::FORMAT_GRAY8, truth.utime, step_, camera);
      } else {  // an empty image (LCM types start uninitialised: every field is set)
        mask = image_t{};
        mask.utime = truth.utime;
        mask.frame_id = step_;
        mask.camera = camera;
        mask.width = mask.height = mask.row_stride = mask.size = 0;
        mask.pixel_format = image_t::FORMAT_GRAY8;
      }
    }
    service_.publish(bus::channel::SIM_TRUTH, truth);
  }

  // --tool auto: the real robot's one hand carries the nudging pad and the gripper; the simulation
  // can make only one of them solid (they share the tool point), so the arm's command picks it.
  void use_gripper(bool gripper) {
    if (gripper == gripper_) return;
    gripper_ = gripper;
    if (gripper_) {
      world_.set_gripper_opening(arm_ ? arm_->gripper : sim::gripper_geometry().max_opening);
    } else {
      world_.set_pusher(world_.pusher_position(), pusher_yaw_);
    }
    log::info() << "tool: " << (gripper_ ? "gripper" : "pad");
  }

  // The gripper is the tool and its fingers, as ARM_STATE last gave them, are not open: they may
  // hold an object.
  bool holding() const { return gripper_ && arm_ && arm_->gripper < 0.9 * sim::gripper_geometry().max_opening; }

  sim_state_t state_message() const {
    sim_state_t msg;
    msg.utime = utime();
    msg.step = step_;
    // With an arm in the scene, its joints as simulated; else the latest ARM_STATE's.
    const std::array<double, 6> simulated = world_.arm_joints();
    for (int i = 0; i < 6; ++i) msg.joints[i] = world_.has_arm() ? simulated[i] : arm_ ? arm_->joints[i] : 0.0;
    // What a gripper's finger sensor would read: the simulated fingers stop on what they hold.
    msg.gripper = gripper_ ? world_.gripper_opening() : -1.0;
    msg.num_objects = world_.num_objects();
    for (int i = 0; i < world_.num_objects(); ++i) {
      const sim::ObjectState st = world_.object(i);
      const sim::Axis3d axis = world_.axis(i);
      object_state_t o;
      o.name = st.name;
      o.pose = bus::to_message(st.position, st.orientation);
      for (int k = 0; k < 3; ++k) {
        o.axis_point[k] = axis.base[k];
        o.axis_direction[k] = axis.direction[k];
      }
      const sim::ImageLine left = world_.axis_in_image(i, 0), right = world_.axis_in_image(i, 1);
      const float nan = std::nanf("");
      o.r_left = left.valid ? static_cast<float>(left.r) : nan;
      o.theta_left = left.valid ? static_cast<float>(left.theta) : nan;
      o.r_right = right.valid ? static_cast<float>(right.r) : nan;
      o.theta_right = right.valid ? static_cast<float>(right.theta) : nan;
      msg.objects.push_back(o);
    }
    msg.pusher = bus::to_message(world_.pusher_position(), sim::yaw_rotation(pusher_yaw_));
    return msg;
  }

 private:
  bus::Service& service_;
  sim::World world_;
  int64_t step_ = 0;
  int64_t steps_per_state_ = 1;
  double end_time_ = std::numeric_limits<double>::infinity();
  double pusher_yaw_ = 0;
  bool gripper_ = false;  // the arm's tool is the gripper (else the pad)
  std::optional<arm_state_t> arm_;
};

// The world's inputs, on the world's BusClock. Live (wall), a message takes effect at the next
// physics step. From a log (the file provider hands messages over as fast as they are read,
// stamped with the wall clock), a message takes effect at simulated time = its utime minus the
// log's origin (LogTimeline: 0 when the first input message's utime looks like simulated time,
// as an arm on --clock sim stamps ARM_STATE with SIM_STATE's utime; else that first utime), the
// same way every run. Bad messages are reported naming the channel, counted and skipped.
class Inputs {
 public:
  Inputs(bus::Service& service, Simulation& sim, BusClock& clock, LogTimeline timeline, bool auto_tool)
      : sim_(sim), clock_(clock), timeline_(timeline) {
    if (auto_tool)
      service.subscriptions().subscribe<arm_command_t>(bus::channel::ARM_COMMAND, [this](const arm_command_t& msg, const std::string&) {
        if (msg.command == arm_command_t::COMMAND_GRASP) sim_.use_gripper(true);
        if (msg.command == arm_command_t::COMMAND_NUDGE) sim_.use_gripper(false);
        // Parked, the one hand shows the pad again, as it did before the grasp: the still before
        // the next nudge shows the hand as the still after it will (with the gripper drawn in
        // one and the pad in the other, the motion segmentation cut out the hand: the demo,
        // 2026-11-30). Not while the fingers hold something.
        if (msg.command == arm_command_t::COMMAND_HOME && !sim_.holding()) sim_.use_gripper(false);
      });
    service.subscriptions().subscribe<arm_state_t>(bus::channel::ARM_STATE, [this](const arm_state_t& msg, const std::string&) {
      catch_up(msg.utime);
      sim_.on_arm_state(msg);  // throws on a bad pose: counted, skipped
    });
    service.subscriptions().subscribe<sim_truth_request_t>(
        bus::channel::SIM_TRUTH_REQUEST, [this](const sim_truth_request_t& msg, const std::string&) {
          catch_up(msg.utime);
          sim_.on_truth_request(!msg.without_masks);
        });
  }

 private:
  void catch_up(int64_t utime) {
    if (clock_.source() != ClockSource::Log) return;  // live: the pacer moves simulated time
    // A stamp on another clock would run the physics for years: refused (counted, skipped)
    // before it moves the clock.
    timeline_.seconds(utime);
    if (const std::optional<int64_t> now = clock_.on_message(utime, Stamp::Sender)) {
      sim_.advance_to(timeline_.seconds(*now));
    }
  }

  Simulation& sim_;
  BusClock& clock_;
  LogTimeline timeline_;
};

// The simulated arm must stand where the workspace the arm service plans with says. The scene
// places it (the camera's sim backend renders the same scene), so a workspace file that
// disagrees is a usage error rather than a silent choice; the simulated base is not turned.
void check_arm_placement(const robot::Workspace& workspace, const std::string& workspace_file, const sim::Scene& scene) {
  if (!scene.arm.present) return;
  if (workspace.base_yaw != 0.0)
    throw FlagError("--workspace: base_yaw_deg must be 0 in simulation (the simulated arm is not turned)");
  if (workspace_file.empty() || std::abs(workspace.shoulder_height - scene.arm.shoulder_height) < 1e-9) return;
  throw FlagError("--workspace " + workspace_file + ": shoulder_height " + std::to_string(workspace.shoulder_height) +
                  " m but " + scene.source + ": arm.shoulder_height " + std::to_string(scene.arm.shoulder_height) +
                  " m: the simulated arm must stand where the arm service plans for it");
}

}  // namespace

int main(int argc, char** argv) {
  return bus::guarded_main("world", [&] {
    bus::Service service("world",
                         "The simulated world: MuJoCo physics of a scene (docs/sim.md). Publishes SIM_STATE,\n"
                         "answers SIM_TRUTH_REQUEST on SIM_TRUTH, puts the pusher (--tool gripper: the gripper)\n"
                         "at ARM_STATE's tool point.");
    std::string scene_file;
    int seed = -1;
    double realtime_factor = 1.0, rate = 25.0, duration = 0.0;
    auto& f = service.flags();
    f.add_string("scene", &scene_file, "scene file (YAML, docs/sim.md)");
    f.add_int("seed", &seed, "seed for placement jitter and noise (-1: the scene's)");
    f.add_double("realtime-factor", &realtime_factor,
                 "simulated seconds per wall-clock second (1: real time, 0: as fast as possible)");
    f.add_double("rate", &rate, "SIM_STATE messages per simulated second");
    f.add_double("duration", &duration, "stop after this many simulated seconds (0: run until stopped)");
    std::string tool = "pad";
    f.add_string("tool", &tool, "the arm's tool: pad (pushes), gripper (grasps; fingers follow ARM_STATE.gripper) or auto "
                                "(the pad, the gripper from a COMMAND_GRASP until the next COMMAND_NUDGE)");
    // Scenes with the arm: its tool and shoulder height are the workspace's, as nudge-arm's.
    const robot::WorkspaceFlags workspace_flags(f, {"tool-length"}, "scenes with the arm: ");
    double log_origin_s = -1;
    f.add_double("log-origin", &log_origin_s,
                 "input from a log: the utime (s) that is simulated time 0 (-1: automatic, docs/sim.md)");
    if (!service.parse(argc, argv)) return 0;
    if (scene_file.empty()) throw FlagError("--scene FILE is required");
    if (!(realtime_factor >= 0 && std::isfinite(realtime_factor))) throw FlagError("--realtime-factor must be >= 0");
    if (!(rate > 0 && std::isfinite(rate))) throw FlagError("--rate must be > 0");
    if (!(duration >= 0 && std::isfinite(duration))) throw FlagError("--duration must be >= 0");
    if (seed < -1) throw FlagError("--seed must be >= 0 (or -1 for the scene's)");
    if (tool != "pad" && tool != "gripper" && tool != "auto") throw FlagError("--tool must be pad, gripper or auto, not '" + tool + "'");
    const robot::Workspace workspace = workspace_flags.resolve();
    if (!(log_origin_s >= 0 || log_origin_s == -1)) throw FlagError("--log-origin must be >= 0 (or -1)");
    const int64_t log_origin = log_origin_s >= 0 ? std::llround(log_origin_s * 1e6) : -1;
    sim::Scene scene;
    try {
      scene = sim::load_scene(scene_file);  // errors name the file and the field
    } catch (const sim::SceneError& e) {
      throw FlagError(e.what());
    }
    if (seed >= 0) scene.seed = static_cast<uint64_t>(seed);
    check_arm_placement(workspace, workspace_flags.file(), scene);

    service.start();
    Simulation sim(service, scene, rate, tool == "gripper", workspace.tool_length);
    if (duration > 0) sim.set_end_time(duration);
    const bool from_log = service.input_is_log();
    // Message time from a log, else the wall clock (paced, or as fast as possible).
    BusClock clock(from_log ? ClockSource::Log : ClockSource::Wall);
    Inputs inputs(service, sim, clock, LogTimeline(log_origin >= 0 ? std::optional<int64_t>(log_origin) : std::nullopt),
                  tool == "auto");
    if (scene.arm.present)
      log::info() << "the PUMA 260 with its tool point " << workspace.tool_length << " m along the flange"
                  << (workspace_flags.file().empty() ? "" : " (" + workspace_flags.file() + ")");
    log::info() << scene_file << ": " << scene.objects.size() << " objects, seed " << scene.seed << ", "
                << (from_log ? "input events applied at their log time"
                             : realtime_factor > 0 ? "realtime factor " + std::to_string(realtime_factor)
                                                   : std::string("as fast as possible"));
    service.publish(bus::channel::SIM_STATE, sim.state_message());  // the state at t = 0

    std::optional<Pacer> pacer;
    if (realtime_factor > 0) pacer.emplace(realtime_factor);
    const int rc = service.run([&]() -> int {
      if (sim.finished()) {
        service.request_stop();
        return 0;
      }
      if (from_log) return 0;  // input events drive the clock (Inputs::catch_up)
      if (realtime_factor == 0) {
        // As fast as possible, looking for input between every published state.
        sim.advance_to_next_state();
        return 0;
      }
      const double target = pacer->target(sim.time());
      sim.advance_to(target);
      service.set_status("t " + std::to_string(sim.time()) + " s, slowed " + std::to_string(pacer->slips()) + "x");
      return pacer->wait_ms(sim.time() + sim.timestep(), target);
    }, 20);
    // A log's events are all applied: simulate on to --duration, as fast as possible.
    if (from_log && rc == 0 && duration > 0) sim.advance_to(duration);
    log::info() << "simulated " << sim.time() << " s";
    return rc;
  });
}
