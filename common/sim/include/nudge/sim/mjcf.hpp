#pragma once
// The MuJoCo model (MJCF text) of a scene, generated from C++ so that scenes need no code.
// Names in the model: bodies "obj<i>" (object i of Scene::objects), their free joints
// "obj<i>_joint", mesh geoms "obj<i>_part<k>"; cameras "left"/"right"; the table plane "table";
// the backdrop "backdrop"; the kinematic pusher: mocap body "pusher" with the geom "pusher_pad".
//
// Collision groups: the table (contype 1) touches objects only, the pusher pad (contype 2)
// touches objects only, objects (contype 3) touch everything. Objects collide with the convex
// hulls of their mesh parts.
#include "nudge/sim/scene.hpp"

#include <Eigen/Core>

#include <string>

namespace nudge::sim {

// Where the pusher waits when it is not pushing: behind the backdrop, out of every view.
const Eigen::Vector3d& pusher_park_position();

// Half sizes (m) of the pusher's pad: thickness along the push, width, height.
const Eigen::Vector3d& pusher_pad_half_size();

// The MJCF text of a scene (objects at the scene's positions exactly; no jitter applied).
// Throws SceneError for an invalid scene.
std::string build_mjcf(const Scene& scene);

}  // namespace nudge::sim
