// Renders every SIM_STATE with a World of its own built from the same scene: objects and the
// pusher are teleported to the state's poses (physics never runs here), then both cameras are
// drawn and published on CAMERA_LEFT / CAMERA_RIGHT with the state's (simulated) utime.
#include "sim_backend.hpp"

#include <optional>

#include "nudge/bus/image.hpp"
#include "nudge/log.hpp"
#include "nudge/sim/state_sync.hpp"
#include "nudge/sim/world.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/snapshot_request_t.hpp"

namespace nudge::camera_service {

namespace {

constexpr const char* kStateChannel = "SIM_STATE";
constexpr const char* kSnapshotRequestChannel = "CAMERA_SNAPSHOT_REQUEST";
constexpr const char* kChannels[2] = {"CAMERA_LEFT", "CAMERA_RIGHT"};
constexpr const char* kSnapshotChannels[2] = {"SNAPSHOT_LEFT", "SNAPSHOT_RIGHT"};
constexpr const char* kCameraNames[2] = {"left", "right"};

Eigen::Vector3d position_of(const pose_t& pose) {
  return {pose.position[0], pose.position[1], pose.position[2]};
}
Eigen::Quaterniond orientation_of(const pose_t& pose) {
  return {pose.orientation[0], pose.orientation[1], pose.orientation[2], pose.orientation[3]};
}

sim::PoseSnapshot poses_of(const sim_state_t& state) {
  if (state.num_objects != static_cast<int32_t>(state.objects.size()))
    throw std::invalid_argument("num_objects disagrees with the objects sent");
  sim::PoseSnapshot poses;
  for (const object_state_t& o : state.objects)
    poses.objects.push_back({o.name, position_of(o.pose), orientation_of(o.pose)});
  poses.pusher_position = position_of(state.pusher);
  poses.pusher_yaw = sim::yaw_of(orientation_of(state.pusher));
  return poses;
}

}  // namespace

int run_sim_camera(bus::Service& service, const SimOptions& options) {
  sim::Scene scene;
  try {
    scene = sim::load_scene(options.scene_file);
  } catch (const sim::SceneError& e) {
    throw FlagError(e.what());  // a usage error: exit code 2, the message names file and field
  }
  if (options.noise_sigma >= 0) scene.render.noise_sigma = options.noise_sigma;
  sim::World world(scene);
  log::info() << "rendering SIM_STATE of " << options.scene_file << " (" << scene.rig.width << "x"
              << scene.rig.height << ", noise " << scene.render.noise_sigma << ")";
  service.start();

  int64_t frame_id = 0, snapshot_id = 0;
  std::optional<int64_t> last_state_utime;
  service.subscriptions().subscribe<sim_state_t>(kStateChannel, [&](const sim_state_t& state, const std::string&) {
    sim::apply_poses(world, poses_of(state));  // throws naming the object: counted, skipped
    last_state_utime = state.utime;
    // Both frames come from one set of poses and share the state's utime (a stereo pair).
    for (int c = 0; c < 2; ++c) {
      service.publish(kChannels[c], bus::to_message(world.render(c), options.pixel_format, state.utime, frame_id,
                                                    kCameraNames[c], options.jpeg_quality));
    }
    ++frame_id;
    if (options.count > 0 && frame_id >= options.count) service.request_stop();
  });
  if (options.snapshots) {
    service.subscriptions().subscribe<snapshot_request_t>(
        kSnapshotRequestChannel, [&](const snapshot_request_t&, const std::string&) {
          if (!last_state_utime) throw std::runtime_error("no SIM_STATE rendered yet: nothing to snapshot");
          for (int c = 0; c < 2; ++c) {
            service.publish(kSnapshotChannels[c],
                            bus::to_message(world.render_snapshot(c), options.pixel_format, *last_state_utime,
                                            snapshot_id, kCameraNames[c], options.jpeg_quality));
          }
          ++snapshot_id;
        });
  }
  return service.run();
}

}  // namespace nudge::camera_service
