#pragma once
// The simulated world: MuJoCo physics of a table, household objects and a kinematic pusher, seen
// by a verged stereo pair rendered offscreen through OSMesa. A pure library (no LCM): the world
// service and the camera's sim backend wrap it.
//
// Deterministic: the same scene (including its seed) and the same calls give bit-identical
// states and images. Not thread-safe: use one World from one thread at a time.
#include "nudge/sim/camera.hpp"
#include "nudge/sim/scene.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <array>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace nudge::sim {

// Failures of MuJoCo (model compilation, rendering context) and misuse of the pusher.
class SimError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ObjectState {
  std::string name;
  std::string kind;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // base centre, world frame
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();   // of the body origin
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // world frame
  double height = 0;  // along the symmetry axis
  double mass = 0;    // kg, contents included
  Eigen::Vector3d centre_of_mass = Eigen::Vector3d::Zero();  // world frame
  double tilt() const;  // angle between the symmetry axis and the world z axis, radians
};

struct StereoImages {
  double time = 0;                  // simulated time of the physics state both were rendered from
  std::array<cv::Mat, 2> colour;    // BGR, CV_8UC3
  std::array<cv::Mat, 2> mask;      // CV_8U: object index + 1, 0 = table/background/pusher (if asked)
};

struct PushResult {
  double start_time = 0, end_time = 0;  // simulated time
  bool contact = false;                 // the pad touched an object
};

class World {
 public:
  // Builds the model (objects placed with the scene's seeded jitter), then simulates
  // scene.physics.settle_time so that objects start at rest. Throws SceneError / SimError.
  explicit World(const Scene& scene);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  const Scene& scene() const { return scene_; }  // with the jittered positions actually used
  const std::string& mjcf() const { return mjcf_; }
  const StereoRig& rig() const { return rig_; }
  const CameraModel& camera(int index) const { return rig_.cameras.at(index); }

  // ---- physics
  double time() const;
  double timestep() const;
  void step(int n = 1);
  void step_for(double seconds);  // whole steps, rounded to the nearest
  // The whole dynamic state: time, generalised positions and velocities, the pusher's position
  // and orientation, the solver's warm start, the fingers' commanded positions and the tool in
  // use (for determinism checks, logging, and rewinding with set_state()).
  std::vector<double> state() const;
  // Restores a state() of a World built from the same scene; stepping on from it reproduces the
  // original run exactly. Throws std::invalid_argument if the size does not match.
  void set_state(const std::vector<double>& state);

  // ---- objects and ground truth
  int num_objects() const { return static_cast<int>(scene_.objects.size()); }
  int object_index(const std::string& name) const;  // -1 if unknown
  ObjectState object(int index) const;
  // Teleports an object (base centre and orientation, world frame) and stops it. For resetting
  // a scene or putting an object back (thesis ch. 7); the caller steps physics afterwards.
  void set_object_pose(int index, const Eigen::Vector3d& position,
                       const Eigen::Quaterniond& orientation);
  // Upright on the table at (x, y) with the given yaw.
  void place_object(int index, const Eigen::Vector2d& xy, double yaw);
  // The object's symmetry axis: its local z axis through the base centre.
  Axis3d axis(int index) const;
  ImageLine axis_in_image(int index, int camera) const;

  // ---- the kinematic pusher (the seam where the arm's end effector will go)
  // Places the pad (its centre) at `position`, its face turned to push along the horizontal
  // direction of angle `yaw` (rad, about world z). Moves instantly: the caller steps physics.
  void set_pusher(const Eigen::Vector3d& position, double yaw);
  void park_pusher();
  Eigen::Vector3d pusher_position() const;
  // A straight push: the pad appears at `from` (must not touch an object: SimError otherwise),
  // moves in a straight line to `to` at `speed` m/s, goes back to `from`, is parked, and the world
  // settles for `settle` s. The pad faces the direction of motion.
  PushResult push(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double speed = 0.05,
                  double settle = 1.0);
  // True when the tool in use (the pad, or the gripper's fingers) touches one of the objects
  // (contacts as of the last step).
  bool pusher_in_contact() const;

  // ---- the gripper (two fingers with V-grooved pads on the same tool point as the pad)
  // Only one tool is in use at a time: set_pusher()/park_pusher()/push() use the pad (the fingers
  // then neither collide nor show), set_end_effector() uses the gripper (the pad then neither
  // collides nor shows). Places the tool point (the gripper's centre) at `position`, the fingers
  // closing along the horizontal direction yaw + 90 deg (the tool's y axis; its x axis, the push
  // direction, is `yaw`), and commands the opening (m, clamped to [0, max_opening]: the diameter
  // of the centred vertical cylinder both grooves touch). The fingers are dynamic: position
  // actuators drive them towards the opening and they stop on what they grip, which is then held
  // by contact and friction only. Moves the tool point instantly: the caller steps physics.
  void set_end_effector(const Eigen::Vector3d& position, double yaw, double opening);
  // The gripper in use, its hand at `position` (yaw as above) and its fingers at `opening` (m,
  // clamped) at once, at rest: a renderer's teleport to a published state (no physics needed).
  void place_gripper(const Eigen::Vector3d& position, double yaw, double opening);
  bool gripper_in_use() const;
  double gripper_opening() const;           // the fingers' actual opening now, m
  double gripper_commanded_opening() const;  // m
  // True when both fingers touch object `index` (contacts as of the last step).
  bool gripper_holds(int index) const;

  // ---- the PUMA 260 (scenes with arm.present; see ArmSpec)
  // Its joints are driven by position servos towards the targets, with the links' gravity and
  // Coriolis forces compensated (as the thesis' controller card holds a pose), so the arm settles
  // on its targets; its links push objects they meet.
  bool has_arm() const;
  // Servo targets, rad, clamped to the joint limits. Throws SimError without an arm.
  void set_arm_targets(const std::array<double, 6>& joints);
  std::array<double, 6> arm_targets() const;
  std::array<double, 6> arm_joints() const;  // where the simulated joints are now, rad
  // Puts the arm at `joints` at rest, targets too (for rendering a published state, or resets).
  void set_arm_joints(const std::array<double, 6>& joints);
  // The flange (DH frame 6, the wrist centre) of the simulated arm, world frame.
  Eigen::Isometry3d arm_flange_pose() const;
  // Mounts the tools on the simulated flange: from then on, every step puts the tool point
  // `tool_length` along the flange's z axis (robot::default_tool()) and turns the pad to the
  // horizontal direction of the flange's x axis, so pushes and grasps happen where the simulated
  // arm really is (servo lag included). set_pusher()/set_end_effector() positions are then
  // overridden at the next step; set_gripper_opening() picks the gripper and its opening.
  // Throws SimError without an arm.
  void mount_tools_on_arm(double tool_length = robot::Workspace{}.tool_length);
  bool tools_on_arm() const;
  // The gripper in use, opening towards `opening` (m, clamped), the tool point where it is.
  void set_gripper_opening(double opening);

  // ---- rendering (OSMesa context created on first use)
  cv::Mat render(int camera);       // BGR, rig width x height
  cv::Mat render_mask(int camera);  // CV_8U, object index + 1, 0 elsewhere
  StereoImages render_stereo(bool masks = false);
  // High-resolution still (scene.render.snapshot_scale x the rig size, e.g. 1280x960) and the
  // camera model that goes with it.
  cv::Mat render_snapshot(int camera);
  cv::Mat render_snapshot_mask(int camera);
  // CV_8U, 255 where the still shows the tool itself (pusher pad or gripper; not its shadow), 0
  // elsewhere: the end effector's pixels, occluded where objects stand in front of it.
  cv::Mat render_snapshot_tool_mask(int camera);
  CameraModel snapshot_camera(int camera) const;
  // Which surface point of which object each pixel shows (ground truth for feature matches: two
  // pixels show the same point of an object when their coordinates agree). CV_32FC3: the point in
  // that object's own frame (metres; origin at its base centre, z up its axis), NaN where no
  // object is seen. From a label pass's depth buffer, so exact to about a pixel's footprint.
  // `mask` (if not null) gets the render_mask() of the same pass.
  cv::Mat render_surface(int camera, cv::Mat* mask = nullptr);
  cv::Mat render_snapshot_surface(int camera, cv::Mat* mask = nullptr);
  bool pusher_visible = true;       // draw the pusher pad / gripper (colour images and masks)

 private:
  cv::Mat draw(int camera, bool snapshot, bool labels, cv::Mat* surface = nullptr);
  cv::Mat surface_points(const cv::Mat& labels, const cv::Mat& depth, const CameraModel& cam) const;
  void use_gripper(bool gripper);
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Scene scene_;
  std::string mjcf_;
  StereoRig rig_;
};

}  // namespace nudge::sim
