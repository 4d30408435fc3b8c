#pragma once
// The MuJoCo model (MJCF text) of a scene, generated from C++ so that scenes need no code.
// Names in the model: bodies "obj<i>" (object i of Scene::objects), their free joints
// "obj<i>_joint", mesh geoms "obj<i>_part<k>"; cameras "left"/"right"; the table plane "table";
// the backdrop "backdrop"; the kinematic pusher: mocap body "pusher" with the geom "pusher_pad";
// the gripper: the free body "hand" (joint "hand_joint", drawn-only geom "hand_palm") welded
// ("hand_weld") to the mocap body, with finger bodies "finger_left"/"finger_right" on slide joints
// "finger_<side>_slide" driven by position actuators "finger_<side>_act", with box geoms
// "finger_<side>_0".."_3" (a V-groove each) and a drawn-only "finger_<side>_stem".
//
// Collision groups: the table (contype 1) touches objects only, the pusher pad (contype 2)
// touches objects only, objects (contype 3) touch everything. The fingers (contype 2,
// conaffinity 0) touch objects only, not each other. Only the tool in use collides: World turns
// the other one's contype/conaffinity to 0 (and moves it to the hidden geom group 3). Objects collide with the convex
// hulls of their mesh parts.
#include "nudge/sim/scene.hpp"

#include <Eigen/Core>

#include <string>

namespace nudge::sim {

// Where the pusher waits when it is not pushing: behind the backdrop, out of every view.
const Eigen::Vector3d& pusher_park_position();

// Half sizes (m) of the pusher's pad: thickness along the push, width, height.
const Eigen::Vector3d& pusher_pad_half_size();

// The two-finger gripper that shares the pad's tool point (docs/sim.md, "The gripper"). Each finger
// carries a V-groove (a concave pad of two flat faces) facing the other finger; the fingers slide
// along the tool's y axis (horizontal, perpendicular to the pad's push direction). The opening is
// the diameter of the vertical cylinder, centred on the tool point, that both grooves just touch.
struct GripperGeometry {
  double max_opening = 0.10;        // m (the arm's "open", docs/robot.md)
  double groove_half_angle = 0.6108652381980153;  // rad (35 deg): each face's normal vs the closing axis
  double face_half_length = 0.0225;  // m, along the face, from the groove's apex
  double face_half_thickness = 0.003;
  double face_half_height = 0.009;   // two rows of faces, centres at z = +-row_offset
  double row_offset = 0.010;
  double friction = 1.0;             // rubber pads
  double finger_mass = 0.05;         // kg, each
  double kp = 200;                   // N/m, the position actuators' gain
  double max_force = 15;             // N, each finger
  double damping = 5;                // N s/m, each slide joint
  double hand_mass = 0.2;            // kg, the body carrying the fingers
  double weld_timeconst = 0.01;      // s, the soft weld of the hand to the tool point
  // The slide joint's position (the groove's apex from the tool point) for an opening, and back.
  double apex_for_opening(double opening) const;
  double opening_for_apex(double apex) const;
};
const GripperGeometry& gripper_geometry();

// The MJCF text of a scene (objects at the scene's positions exactly; no jitter applied).
// Throws SceneError for an invalid scene.
std::string build_mjcf(const Scene& scene);

}  // namespace nudge::sim
