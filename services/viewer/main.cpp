// viewer: what the robot sees and thinks, in a browser (docs/operator.md). Serves a page on
// localhost: both cameras at their frame rate with the symmetry lines, tracked lines and boxes on
// top, the candidates and the planned push as a top view of the table (thesis fig. 6.6), the
// segmentation masks, the supervisor's timeline, and every service's health from HEARTBEAT. On a
// replayed log (nudge-replay, scripts/replay.sh) the page also pauses and steps the replay: it
// posts to /api/replay and this service publishes a replay_command_t on REPLAY_COMMAND.
//
// HTTP: GET /                 the page
//       GET /api/state        everything but images, as JSON (viewer::ViewModel::to_json)
//       GET /api/frame/NAME?after=SEQ[&wait=MS]   the camera's next JPEG (waits up to 1 s; 204 if none)
//       GET /api/mask/I       the I-th segmentation mask (PNG)
// It also shows the processes nudge-launch runs (PROCESS_STATUS).
//       POST /api/replay?command=play|pause|step|speed[&speed=X]
// Eigen (through the supervisor's scene geometry) before httplib.h, whose macros break Eigen's
// headers when they come after it.
#include "nudge/supervisor/scene.hpp"

#include <httplib.h>

#include <algorithm>
#include <cctype>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "nudge/arm_command_t.hpp"
#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/bus/viewer_convert.hpp"
#include "nudge/candidates_t.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/image_t.hpp"
#include "nudge/log.hpp"
#include "nudge/process_status_t.hpp"
#include "nudge/replay_command_t.hpp"
#include "nudge/replay_status_t.hpp"
#include "nudge/segmentation_t.hpp"
#include "nudge/supervisor_state_t.hpp"
#include "nudge/symmetry_lines_t.hpp"
#include "nudge/timing.hpp"
#include "nudge/track_t.hpp"
#include "nudge/viewer/replay_pacer.hpp"
#include "nudge/viewer/view_model.hpp"
#include "page.hpp"

#include <opencv2/imgcodecs.hpp>

using namespace nudge;
namespace channel = nudge::bus::channel;

namespace {

// CAMERA_LEFT -> "left", CAMERA -> "mono", LEFT_EYE -> "left_eye": the camera's name on the page.
std::string camera_name(const std::string& image_channel) {
  std::string name = image_channel;
  const std::string prefix = std::string(channel::CAMERA) + "_";
  if (name == channel::CAMERA) return "mono";
  if (name.rfind(prefix, 0) == 0) name = name.substr(prefix.size());
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
  return name;
}

viewer::ImageLine to_line(const symmetry_line_t& l) {
  viewer::ImageLine out;
  out.r = l.r, out.theta = l.theta, out.votes = l.votes;
  out.x1 = l.x1, out.y1 = l.y1, out.x2 = l.x2, out.y2 = l.y2;
  out.seg_x1 = l.seg_x1, out.seg_y1 = l.seg_y1, out.seg_x2 = l.seg_x2, out.seg_y2 = l.seg_y2;
  return out;
}

std::string track_status_name(int8_t status) {
  switch (status) {
    case track_t::STATUS_IDLE: return "idle";
    case track_t::STATUS_INITIALISING: return "initialising";
    case track_t::STATUS_TRACKING: return "tracking";
    case track_t::STATUS_LOST: return "lost";
  }
  throw std::invalid_argument("track_t.status " + std::to_string(status) + " is unknown");
}

std::string heartbeat_state_name(int8_t state) {
  switch (state) {
    case heartbeat_t::STATE_STARTING: return "starting";
    case heartbeat_t::STATE_RUNNING: return "running";
    case heartbeat_t::STATE_DEGRADED: return "degraded";
    case heartbeat_t::STATE_STOPPING: return "stopping";
  }
  return "state " + std::to_string(state);
}

std::string replay_state_name(int8_t state) {
  switch (state) {
    case replay_status_t::STATE_PLAYING: return "playing";
    case replay_status_t::STATE_PAUSED: return "paused";
    case replay_status_t::STATE_FINISHED: return "finished";
  }
  return "state " + std::to_string(state);
}

// Replay commands the page posts (HTTP threads), published from the service's own thread.
class CommandQueue {
 public:
  void push(const replay_command_t& command) {
    std::lock_guard<std::mutex> lock(mutex_);
    commands_.push_back(command);
  }
  std::vector<replay_command_t> take() {
    std::lock_guard<std::mutex> lock(mutex_);
    return std::exchange(commands_, {});
  }

 private:
  std::mutex mutex_;
  std::vector<replay_command_t> commands_;
};

replay_command_t replay_command_from_request(const httplib::Request& request) {
  replay_command_t command{};
  command.utime = wall_utime();
  command.speed = 0;
  switch (viewer::replay_command_from_name(request.get_param_value("command"))) {
    case viewer::ReplayCommand::kPlay: command.command = replay_command_t::COMMAND_PLAY; break;
    case viewer::ReplayCommand::kPause: command.command = replay_command_t::COMMAND_PAUSE; break;
    case viewer::ReplayCommand::kStep: command.command = replay_command_t::COMMAND_STEP; break;
    case viewer::ReplayCommand::kSpeed:
      command.command = replay_command_t::COMMAND_SPEED;
      command.speed = parse_double(request.get_param_value("speed"), "speed");
      if (!(command.speed > 0)) throw std::invalid_argument("speed must be > 0");
      break;
  }
  return command;
}

void subscribe_camera(bus::Service& service, viewer::ViewModel& model, const std::string& image_channel) {
  const std::string name = camera_name(image_channel);
  auto& subs = service.subscriptions();
  subs.subscribe<image_t>(image_channel, [&model, name](const image_t& msg, const std::string&) {
    if (msg.pixel_format == image_t::FORMAT_MJPEG) {  // sent as JPEG: served as it is
      model.set_frame_jpeg(name, msg.data, msg.width, msg.height, msg.utime);
    } else {
      model.set_frame(name, bus::to_mat(msg), msg.utime);  // throws ImageError naming the image
    }
  });
  subs.subscribe<symmetry_lines_t>(channel::derived(image_channel, channel::SYMMETRY),
                                   [&model, name](const symmetry_lines_t& msg, const std::string&) {
                                     std::vector<viewer::ImageLine> lines;
                                     for (const auto& l : msg.lines) lines.push_back(to_line(l));
                                     model.set_lines(name, std::move(lines), msg.utime);
                                   });
  subs.subscribe<track_t>(channel::derived(image_channel, channel::TRACK),
                          [&model, name](const track_t& msg, const std::string&) {
                            viewer::TrackOverlay track;
                            track.status = track_status_name(msg.status);
                            track.reason = msg.reason;
                            track.line = to_line(msg.line);
                            for (int i = 0; i < 4; ++i)
                              for (int j = 0; j < 2; ++j) track.box[i][j] = msg.box[i][j];
                            track.utime = msg.utime;
                            model.set_track(name, track);
                          });
}

// `scene` (--calibration): the candidates are drawn in the arm's world frame, as the supervisor
// converts them, so that the planned push (world frame) goes through its target's dot.
void subscribe_robot(bus::Service& service, viewer::ViewModel& model,
                     const std::optional<supervisor::SceneGeometry>& scene) {
  auto& subs = service.subscriptions();
  subs.subscribe<candidates_t>(channel::CANDIDATES, [&model, &scene](const candidates_t& msg, const std::string&) {
    std::vector<viewer::Candidate> candidates(msg.num_candidates);
    for (int i = 0; i < msg.num_candidates; ++i) {
      Eigen::Vector3d p(msg.position[i][0], msg.position[i][1], msg.position[i][2]);
      if (scene) p = scene->table_to_world(p);
      std::copy_n(p.data(), 3, candidates[i].position);
      candidates[i].cluster_size = msg.cluster_size[i];
    }
    model.set_candidates(std::move(candidates), msg.utime, scene.has_value());
  });
  subs.subscribe<arm_command_t>(channel::ARM_COMMAND, [&model](const arm_command_t& msg, const std::string&) {
    if (msg.command != arm_command_t::COMMAND_NUDGE) return;
    viewer::PlannedPush push;
    std::copy(msg.target.position, msg.target.position + 3, push.target);
    std::copy(msg.direction, msg.direction + 3, push.direction);
    push.start_distance = msg.start_distance;
    push.stop_distance = msg.stop_distance;
    push.utime = msg.utime;
    model.set_push(push);
  });
  subs.subscribe<supervisor_state_t>(
      channel::SUPERVISOR_STATE, [&model](const supervisor_state_t& msg, const std::string&) {
        model.observe_state(bus::state_entry_of(msg));
      });
  subs.subscribe<segmentation_t>(channel::SEGMENTATION, [&model](const segmentation_t& msg, const std::string&) {
    viewer::Segmentation seg;
    seg.attempt = msg.attempt;
    seg.utime = msg.utime;
    seg.pixels = msg.mask_pixels;
    seg.width = msg.mask.width;
    seg.height = msg.mask.height;
    if (msg.mask.pixel_format == image_t::FORMAT_PNG) {
      seg.png = msg.mask.data;
    } else {
      cv::imencode(".png", bus::to_mat(msg.mask), seg.png);
    }
    model.add_segmentation(std::move(seg));
  });
}

void subscribe_health(bus::Service& service, viewer::ViewModel& model) {
  auto& subs = service.subscriptions();
  subs.subscribe_timed<heartbeat_t>(
      channel::HEARTBEAT, [&model](const heartbeat_t& msg, const std::string&, int64_t receive_utime) {
        viewer::Heartbeat hb;
        hb.service = msg.service;
        hb.instance = msg.instance;
        hb.pid = msg.pid;
        hb.state = heartbeat_state_name(msg.state);
        hb.messages_in = msg.messages_in;
        hb.messages_out = msg.messages_out;
        hb.errors = msg.errors;
        hb.status = msg.status;
        model.observe_heartbeat(hb, msg.utime, receive_utime);
      });
  subs.subscribe<replay_status_t>(channel::REPLAY_STATUS, [&model](const replay_status_t& msg, const std::string&) {
    viewer::ReplayStatus status;
    status.log = msg.log;
    status.state = replay_state_name(msg.state);
    status.speed = msg.speed;
    status.position_utime = msg.position_utime;
    status.start_utime = msg.start_utime;
    status.end_utime = msg.end_utime;
    status.events = msg.events;
    status.total_events = msg.total_events;
    status.received_wall_utime = wall_utime();
    model.set_replay(status);
  });
  subs.subscribe<process_status_t>(channel::PROCESS_STATUS, [&model](const process_status_t& msg, const std::string&) {
    model.set_processes(bus::process_rows_of(msg));
  });
}

void add_routes(httplib::Server& server, viewer::ViewModel& model, CommandQueue& commands) {
  server.Get("/", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(viewer_service::kIndexHtml, "text/html; charset=utf-8");
  });
  server.Get("/api/state", [&model](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_content(model.to_json(wall_utime()).dump(), "application/json");
  });
  server.Get(R"(/api/frame/([a-z0-9_]+))", [&model](const httplib::Request& req, httplib::Response& res) {
    int after = -1, wait_ms = 1000;
    try {
      if (req.has_param("after")) after = parse_int(req.get_param_value("after"), "after");
      if (req.has_param("wait")) wait_ms = std::clamp(parse_int(req.get_param_value("wait"), "wait"), 0, 5000);
    } catch (const std::exception& e) {
      res.status = 400;
      res.set_content(std::string("bad frame request: ") + e.what() + "\n", "text/plain");
      return;
    }
    viewer::JpegFrame frame;
    res.set_header("Cache-Control", "no-store");
    if (!model.wait_frame(req.matches[1], after, wait_ms, &frame)) {
      res.status = 204;  // nothing newer in time: the page asks again
      return;
    }
    res.set_header("X-Frame-Seq", std::to_string(frame.seq));
    res.set_header("X-Frame-Utime", std::to_string(frame.utime));
    res.set_content(std::string(frame.jpeg.begin(), frame.jpeg.end()), "image/jpeg");
  });
  server.Get(R"(/api/mask/(\d+))", [&model](const httplib::Request& req, httplib::Response& res) {
    std::vector<uint8_t> png;
    if (!model.mask_png(std::stoul(req.matches[1]), &png)) {
      res.status = 404;
      res.set_content("no such mask", "text/plain");
      return;
    }
    res.set_content(std::string(png.begin(), png.end()), "image/png");
  });
  // With a content reader: a POST with no body and no Content-Length (`curl -X POST URL`) is
  // answered at once; httplib would otherwise wait for the client to close before calling us.
  server.Post("/api/replay", [&commands](const httplib::Request& req, httplib::Response& res,
                                         const httplib::ContentReader& content_reader) {
    if (req.has_header("Content-Length")) content_reader([](const char*, size_t) { return true; });  // ignored
    try {
      commands.push(replay_command_from_request(req));
      res.set_content("ok\n", "text/plain");
    } catch (const std::exception& e) {
      res.status = 400;
      res.set_content(std::string("bad replay command: ") + e.what() + "\n", "text/plain");
    }
  });
}

}  // namespace

int main(int argc, char** argv) {
  return bus::guarded_main("viewer", [&] {
    bus::Service service("viewer", "What the robot sees and thinks, in a browser (docs/operator.md).");
    std::string cameras = std::string(channel::CAMERA_LEFT) + "," + channel::CAMERA_RIGHT, bind = "127.0.0.1";
    std::string calibration;
    int port = 8088, jpeg_quality = 80;
    double dead_after_s = 2.5;
    auto& f = service.flags();
    f.add_string("cameras", &cameras, "comma-separated image channels to show (their SYMMETRY_*/TRACK_* on top)");
    f.add_int("port", &port, "HTTP port of the page");
    f.add_string("bind", &bind, "address to serve on (127.0.0.1: this machine only)");
    f.add_int("jpeg-quality", &jpeg_quality, "JPEG quality of the frames sent to the page, 1-100");
    f.add_double("dead-after", &dead_after_s, "a service silent for longer than this many seconds is shown dead");
    f.add_string("calibration", &calibration,
                 "the supervisor's calibration file: candidates drawn in the arm's frame, as the push (default: "
                 "the triangulation's table frame)");
    if (!service.parse(argc, argv)) return 0;
    if (port < 0 || port > 65535) throw FlagError("--port must be in 0..65535");
    if (jpeg_quality < 1 || jpeg_quality > 100) throw FlagError("--jpeg-quality must be in 1..100");
    if (!(dead_after_s > 0)) throw FlagError("--dead-after must be > 0 seconds");
    const std::vector<std::string> camera_channels = split_list(cameras);
    if (camera_channels.empty()) throw FlagError("--cameras names no channel");

    // A file that cannot be read is named (SceneGeometry::load) before anything is served.
    std::optional<supervisor::SceneGeometry> scene;
    if (!calibration.empty()) scene = supervisor::SceneGeometry::load(calibration);

    viewer::ViewModel model(dead_after_s, jpeg_quality);
    CommandQueue commands;
    httplib::Server server;
    add_routes(server, model, commands);
    if (!server.bind_to_port(bind.c_str(), port))
      throw std::runtime_error("cannot serve on " + bind + ":" + std::to_string(port) + " (in use?)");
    std::thread http([&] { server.listen_after_bind(); });
    log::info() << "serving the page on http://" << bind << ":" << port << "/";

    service.start();
    for (const auto& c : camera_channels) subscribe_camera(service, model, c);
    subscribe_robot(service, model, scene);
    subscribe_health(service, model);
    const int code = service.run([&] {
      for (const replay_command_t& command : commands.take()) service.publish(channel::REPLAY_COMMAND, command);
      return 20;
    });
    server.stop();
    http.join();
    return code;
  });
}
