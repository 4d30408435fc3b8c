// camera: publishes frames from image files, a video or a capture device on CAMERA_* channels.
// Stereo: --left SRC --right SRC publish CAMERA_LEFT / CAMERA_RIGHT with one shared utime per pair.
// Simulation: --source sim --scene FILE renders the world service's SIM_STATE (sim_backend.cpp,
// built only with the simulator, NUDGE_CAMERA_SIM: a real robot's build needs no MuJoCo/OSMesa).
#include <sstream>
#include <thread>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/camera/source.hpp"
#include "nudge/log.hpp"
#include "nudge/timing.hpp"
#include "sim_backend.hpp"

using namespace nudge;

namespace {

struct Stream {
  std::unique_ptr<camera::FrameSource> source;
  std::string channel, camera_name;
};

#ifdef NUDGE_CAMERA_SIM
constexpr const char* kSimUsage =
    "Simulation: --source sim --scene FILE renders every SIM_STATE as a stereo pair (unless it waited past --max-lag-ms).";
#else
constexpr const char* kSimUsage =
    "Simulation (--source sim): not in this build, which has no simulator (MuJoCo/OSMesa).";
#endif

}  // namespace

int main(int argc, char** argv) {
  return bus::guarded_main("camera", [&] {
    bus::Service service("camera",
                         "Publishes camera frames. Sources: images:GLOB, video:PATH, device:N.\n"
                         "Mono: --source SRC [--channel CAMERA]. Stereo: --left SRC --right SRC.\n" +
                             std::string(kSimUsage));
    std::string source_spec, left_spec, right_spec, channel = bus::channel::CAMERA, format = "gray";
    double rate = 25.0;
    bool loop = false;
    int count = 0, jpeg_quality = 90;
    auto& f = service.flags();
    f.add_string("source", &source_spec, "mono source");
    f.add_string("left", &left_spec, "left source of a stereo pair (CAMERA_LEFT)");
    f.add_string("right", &right_spec, "right source of a stereo pair (CAMERA_RIGHT)");
    f.add_string("channel", &channel, "channel for a mono source");
    f.add_string("format", &format, "pixel format sent: gray, bgr, rgb, jpeg, png");
    f.add_int("jpeg-quality", &jpeg_quality, "JPEG quality for --format jpeg");
    f.add_double("rate", &rate, "frames per second; 0 = as fast as possible");
    f.add_bool("loop", &loop, "start again at the end of a file source");
    f.add_int("count", &count, "stop after this many frames (pairs); 0 = no limit");
    camera_service::SimOptions sim;
    f.add_string("scene", &sim.scene_file, "--source sim: the world service's scene file");
    f.add_double("noise", &sim.noise_sigma, "--source sim: Gaussian pixel noise sigma (-1: the scene's)");
    f.add_int("max-lag-ms", &sim.max_lag_ms,
              "--source sim: a state that waited longer in the input queue is not drawn, its frame counted missed "
              "(a camera slower than the world stays current; 0: draw every state, the supervisor's frame counts "
              "assume it)");
    f.add_int("motion-blur", &sim.motion_blur,
              "--source sim: renders averaged over the interval since the last state (0: sharp)");
    f.add_bool("snapshots", &sim.snapshots,
               "--source sim: answer CAMERA_SNAPSHOT_REQUEST with 1280x960 stills on SNAPSHOT_LEFT/RIGHT");
    std::string snapshot_format;
    f.add_string("snapshot-format", &snapshot_format,
                 "pixel format of the stills (gray, bgr, rgb, jpeg, png; default: --format's). Colour stills "
                 "segment better (motion segmentation takes the largest change over the colour channels)");
    if (!service.parse(argc, argv)) return 0;
    if (rate < 0) throw FlagError("--rate must be >= 0");
    if (sim.max_lag_ms < 0) throw FlagError("--max-lag-ms must be >= 0");
    if (count < 0) throw FlagError("--count must be >= 0");
    const int8_t pixel_format = bus::format_from_name(format);
    if (source_spec == "sim") {
#ifndef NUDGE_CAMERA_SIM
      throw FlagError("--source sim: this nudge-camera was built without the simulator (nudge_sim: MuJoCo and "
                      "OSMesa); build with them to render SIM_STATE (docs/sim.md)");
#else
      // Frames follow the simulated clock (one pair per SIM_STATE): --rate and --loop do not apply.
      if (!left_spec.empty() || !right_spec.empty()) throw FlagError("--source sim renders both cameras itself: no --left/--right");
      if (sim.scene_file.empty()) throw FlagError("--source sim needs --scene FILE");
      if (sim.motion_blur < 0 || sim.motion_blur > 32) throw FlagError("--motion-blur must be in [0, 32]");
      sim.pixel_format = pixel_format;
      sim.snapshot_format = snapshot_format.empty() ? pixel_format : bus::format_from_name(snapshot_format);
      sim.jpeg_quality = jpeg_quality;
      sim.count = count;
      return camera_service::run_sim_camera(service, sim);
#endif
    }
    if (!sim.scene_file.empty() || sim.snapshots) throw FlagError("--scene and --snapshots need --source sim");

    std::vector<Stream> streams;
    if (!left_spec.empty() || !right_spec.empty()) {
      if (left_spec.empty() || right_spec.empty() || !source_spec.empty()) {
        throw FlagError("stereo needs both --left and --right (and no --source)");
      }
      streams.push_back({camera::open_source(left_spec), bus::channel::CAMERA_LEFT, "left"});
      streams.push_back({camera::open_source(right_spec), bus::channel::CAMERA_RIGHT, "right"});
    } else {
      if (source_spec.empty()) throw FlagError("give --source SRC, or --left SRC --right SRC");
      streams.push_back({camera::open_source(source_spec), channel, "mono"});
    }
    for (const auto& s : streams) log::info() << s.channel << " <- " << s.source->describe();
    service.start();

    const int64_t period_us = rate > 0 ? static_cast<int64_t>(1e6 / rate) : 0;
    int64_t next_frame = wall_utime();
    int64_t frame_id = 0;
    std::vector<cv::Mat> frames(streams.size());
    auto publish_next = [&]() -> int {
      const int64_t now = wall_utime();
      if (now < next_frame) return static_cast<int>((next_frame - now) / 1000);
      // Read one frame from every stream; all share the utime of this capture.
      for (size_t i = 0; i < streams.size(); ++i) {
        if (streams[i].source->read(&frames[i])) continue;
        if (!loop || !streams[i].source->rewind() || !streams[i].source->read(&frames[i])) {
          log::info() << streams[i].source->describe() << " finished after " << frame_id << " frames";
          service.request_stop();
          return 0;
        }
      }
      const int64_t utime = wall_utime();
      for (size_t i = 0; i < streams.size(); ++i) {
        service.publish(streams[i].channel,
                        bus::to_message(frames[i], pixel_format, utime, frame_id, streams[i].camera_name, jpeg_quality));
      }
      ++frame_id;
      if (count > 0 && frame_id >= count) service.request_stop();
      next_frame = period_us > 0 ? std::max(next_frame + period_us, now) : now;
      return period_us > 0 ? static_cast<int>(period_us / 1000) : 0;
    };
    return service.run(publish_next, 20);
  });
}
