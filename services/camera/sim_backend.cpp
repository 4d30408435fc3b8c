// Renders every SIM_STATE with a World of its own built from the same scene: objects and the
// pusher are teleported to the state's poses (physics never runs here), then both cameras are
// drawn and published on CAMERA_LEFT / CAMERA_RIGHT with the state's (simulated) utime. With
// --max-lag-ms, states that waited in the input queue longer are skipped (a slow camera stays
// current instead of lagging seconds behind the world).
#include "sim_backend.hpp"

#include <algorithm>
#include <optional>
#include <random>
#include <vector>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/bus/pose_convert.hpp"
#include "nudge/log.hpp"
#include "nudge/sim/sensor.hpp"
#include "nudge/sim/state_sync.hpp"
#include "nudge/sim/world.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/snapshot_request_t.hpp"
#include "nudge/timing.hpp"
#include "nudge/bus/sim_convert.hpp"

namespace nudge::camera_service {

namespace {

constexpr const char* kChannels[2] = {bus::channel::CAMERA_LEFT, bus::channel::CAMERA_RIGHT};
constexpr const char* kSnapshotChannels[2] = {bus::channel::SNAPSHOT_LEFT, bus::channel::SNAPSHOT_RIGHT};
constexpr const char* kCameraNames[2] = {"left", "right"};
// A still waits at most this long without a new state (wall time) for a state at or after its
// request's time, then shows the newest state there is.
constexpr int64_t kNoStateUs = 500000;
// A request stamped this far beyond the newest state is on another clock (wall time).
constexpr int64_t kOtherClockUs = 5000000;

}  // namespace

int run_sim_camera(bus::Service& service, const SimOptions& options) {
  sim::Scene scene;
  try {
    scene = sim::load_scene(options.scene_file);
  } catch (const sim::SceneError& e) {
    throw FlagError(e.what());  // a usage error: exit code 2, the message names file and field
  }
  if (options.noise_sigma >= 0) scene.render.noise_sigma = options.noise_sigma;
  const bool blur = options.motion_blur > 1;
  const double noise_sigma = scene.render.noise_sigma;
  if (blur) scene.render.noise_sigma = 0;  // noise goes on the blurred frame, not on every sub-render
  sim::World world(scene);
  log::info() << "rendering SIM_STATE of " << options.scene_file << " (" << scene.rig.width << "x"
              << scene.rig.height << ", noise " << noise_sigma << ")";
  service.start();

  int64_t frame_id = 0;
  // Each camera numbers its own stills (image_t.frame_id is per camera): a right-only still (the
  // learning views) is no gap on SNAPSHOT_LEFT, and a gap is a lost still.
  int64_t snapshot_ids[2] = {0, 0};
  std::optional<int64_t> last_state_utime;
  std::optional<sim::PoseSnapshot> previous;
  // One camera's frame: sharp, or the mean of renders spread over the interval since the last
  // state (motion blur), with the sensor noise added once, seeded by scene seed and frame.
  auto render = [&](int camera, const sim::PoseSnapshot& poses) {
    if (!blur || !previous) return world.render(camera);
    std::vector<cv::Mat> renders;
    for (int k = 1; k <= options.motion_blur; ++k) {
      sim::apply_poses(world, sim::interpolate_poses(*previous, poses, static_cast<double>(k) / options.motion_blur));
      renders.push_back(world.render(camera));
    }
    cv::Mat exposure = sim::average_frames(renders);
    std::mt19937_64 rng(scene.seed * 1000003u + static_cast<uint64_t>(frame_id) * 2 + camera);
    sim::add_sensor_noise(exposure, noise_sigma, rng);
    cv::Mat out;
    exposure.convertTo(out, CV_8UC3);
    return out;
  };
  // Stills (CAMERA_SNAPSHOT_REQUEST). A still shows a state at or after the request's time (the
  // requester's simulated clock): the requester saw that state, and a still of an earlier one may
  // show the arm before it parked. The camera handles its input in order, so when a request comes
  // it has often drawn only the state before the one the requester saw; the request then waits
  // for the next state (stills of the state before were refused as "taken before we asked", and a
  // loaded camera lost every still of an attempt that way). Repeated requests fold into one.
  std::optional<int64_t> pending[2];  // per camera: the still must show a state at or after this
  int64_t last_state_wall = 0;
  auto take_still = [&](int c, const char* why) {
    if (why) log::warn() << kCameraNames[c] << " still: " << why << "; it shows the newest state, " << *last_state_utime;
    service.publish(kSnapshotChannels[c], bus::to_message(world.render_snapshot(c), options.snapshot_format, *last_state_utime,
                                                          snapshot_ids[c]++, kCameraNames[c], options.jpeg_quality));
    pending[c].reset();
  };
  // Answers the stills whose time the newest drawn state has reached; with a reason (no state for a
  // while: the world paused or stopped, or the input ended), every waiting still, with the newest
  // state there is.
  auto answer = [&](const char* stale_reason) {
    for (int c = 0; c < 2; ++c)
      if (pending[c] && last_state_utime && (stale_reason || *last_state_utime >= *pending[c])) take_still(c, stale_reason);
  };
  int64_t skipped = 0;
  service.subscriptions().subscribe_timed<sim_state_t>(bus::channel::SIM_STATE, [&](const sim_state_t& state, const std::string&,
                                                                                    int64_t receive_utime) {
    last_state_wall = wall_utime();  // a state came, drawn or not: the world runs
    // A state that waited in the queue past the lag limit is not drawn: a camera that cannot draw
    // every state shows the newest ones rather than falling further behind (its frame id is used
    // up, so the gap is seen downstream as a missed frame).
    if (options.max_lag_ms > 0 && wall_utime() - receive_utime > options.max_lag_ms * 1000) {
      if (skipped++ % 50 == 0)
        log::warn() << "state " << state.utime << " waited " << (wall_utime() - receive_utime) / 1000
                    << " ms (over --max-lag-ms): not drawn; " << skipped << " skipped so far";
      ++frame_id;
      return;
    }
    const sim::PoseSnapshot poses = bus::poses_of(state);
    sim::apply_poses(world, poses);  // throws naming the object: counted, skipped
    last_state_utime = state.utime;
    // Both frames come from one set of poses and share the state's utime (a stereo pair).
    for (int c = 0; c < 2; ++c) {
      service.publish(kChannels[c], bus::to_message(render(c, poses), options.pixel_format, state.utime, frame_id,
                                                    kCameraNames[c], options.jpeg_quality));
    }
    previous = poses;
    if (blur) sim::apply_poses(world, poses);  // snapshots show the state itself
    ++frame_id;
    answer(nullptr);
    if (options.count > 0 && frame_id >= options.count) service.request_stop();
  });
  if (options.snapshots) {
    service.subscriptions().subscribe<snapshot_request_t>(
        bus::channel::CAMERA_SNAPSHOT_REQUEST, [&](const snapshot_request_t& request, const std::string&) {
          if (!last_state_utime) throw std::runtime_error("no SIM_STATE rendered yet: nothing to snapshot");
          if (request.cameras < snapshot_request_t::CAMERAS_BOTH || request.cameras > snapshot_request_t::CAMERAS_RIGHT)
            throw std::invalid_argument("snapshot request: unknown cameras value " + std::to_string(request.cameras));
          // A time far beyond the newest state is another clock's (a wall-clock requester): now.
          const bool other_clock = request.utime - *last_state_utime > kOtherClockUs;
          for (int c = 0; c < 2; ++c) {
            const int8_t this_camera = c == 0 ? snapshot_request_t::CAMERAS_LEFT : snapshot_request_t::CAMERAS_RIGHT;
            if (request.cameras != snapshot_request_t::CAMERAS_BOTH && request.cameras != this_camera) continue;
            const int64_t due = other_clock ? *last_state_utime : request.utime;
            pending[c] = pending[c] ? std::max(*pending[c], due) : due;
          }
          answer(nullptr);
        });
  }
  // One pair per world state (README; the integration tests count them) unless --max-lag-ms:
  // SIM_STATE keeps LCM's queue of 30 whatever --queue says, so a camera that falls behind draws
  // its backlog up to --max-lag-ms late instead of losing states to a short queue
  // (docs/reliability.md, "Soak").
  service.subscriptions().set_stream_queue_capacity(30);
  const int code = service.run([&]() -> int {
    if (wall_utime() - last_state_wall > kNoStateUs) answer("no state at or after the request's time came");
    return 20;
  });
  answer("the camera stopped before a state at or after the request's time came");
  if (skipped > 0) log::info() << skipped << " states not drawn: they waited past --max-lag-ms";
  return code;
}

}  // namespace nudge::camera_service
