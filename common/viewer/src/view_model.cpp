#include "nudge/viewer/view_model.hpp"

#include <opencv2/imgcodecs.hpp>

#include <chrono>

namespace nudge::viewer {

using nlohmann::json;

namespace {

constexpr size_t kRateFrames = 10;  // the frame rate is measured over this many frames

json line_json(const ImageLine& l) {
  return {{"r", l.r},   {"theta", l.theta}, {"votes", l.votes}, {"x1", l.x1},         {"y1", l.y1},
          {"x2", l.x2}, {"y2", l.y2},       {"sx1", l.seg_x1},  {"sy1", l.seg_y1},    {"sx2", l.seg_x2},
          {"sy2", l.seg_y2}};
}

json vec3(const double v[3]) { return json::array({v[0], v[1], v[2]}); }

// Frames per second from the data stamps of the last frames (the rate the camera sends at,
// whatever the page manages to fetch).
double frame_rate(const std::deque<int64_t>& utimes) {
  if (utimes.size() < 2) return 0;
  const double span_s = (utimes.back() - utimes.front()) * 1e-6;
  return span_s > 0 ? (utimes.size() - 1) / span_s : 0;
}

}  // namespace

ViewModel::ViewModel(double dead_after_s, int jpeg_quality) : jpeg_quality_(jpeg_quality), health_(dead_after_s) {}

ViewModel::Camera& ViewModel::camera(const std::string& name) { return cameras_[name]; }

void ViewModel::note_frame(Camera& cam, int width, int height, int64_t utime) {
  cam.frame.seq += 1;
  cam.frame.utime = utime;
  cam.frame.width = width;
  cam.frame.height = height;
  // A log played again starts the rate afresh.
  if (!cam.recent_utimes.empty() && utime <= cam.recent_utimes.back()) cam.recent_utimes.clear();
  cam.recent_utimes.push_back(utime);
  while (cam.recent_utimes.size() > kRateFrames) cam.recent_utimes.pop_front();
}

void ViewModel::set_frame(const std::string& name, const cv::Mat& image, int64_t utime) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    Camera& cam = camera(name);
    cam.image = image;
    cam.frame.jpeg.clear();
    note_frame(cam, image.cols, image.rows, utime);
  }
  frame_arrived_.notify_all();
}

void ViewModel::set_frame_jpeg(const std::string& name, std::vector<uint8_t> jpeg, int width, int height,
                               int64_t utime) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    Camera& cam = camera(name);
    cam.image.release();
    cam.frame.jpeg = std::move(jpeg);
    note_frame(cam, width, height, utime);
  }
  frame_arrived_.notify_all();
}

bool ViewModel::wait_frame(const std::string& name, int64_t after_seq, int timeout_ms, JpegFrame* out) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto newer = [&] {
    const auto it = cameras_.find(name);
    return it != cameras_.end() && it->second.frame.seq > after_seq;
  };
  if (!frame_arrived_.wait_for(lock, std::chrono::milliseconds(timeout_ms), newer)) return false;
  Camera& cam = cameras_.at(name);
  if (cam.frame.jpeg.empty() && !cam.image.empty())  // encoded once per frame, whoever asks
    cv::imencode(".jpg", cam.image, cam.frame.jpeg, {cv::IMWRITE_JPEG_QUALITY, jpeg_quality_});
  *out = cam.frame;
  return true;
}

void ViewModel::set_lines(const std::string& name, std::vector<ImageLine> lines, int64_t utime) {
  std::lock_guard<std::mutex> lock(mutex_);
  Camera& cam = camera(name);
  cam.lines = std::move(lines);
  cam.lines_utime = utime;
}

void ViewModel::set_track(const std::string& name, const TrackOverlay& track) {
  std::lock_guard<std::mutex> lock(mutex_);
  Camera& cam = camera(name);
  cam.track = track;
  cam.has_track = true;
}

void ViewModel::set_candidates(std::vector<Candidate> candidates, int64_t utime, bool in_world_frame) {
  std::lock_guard<std::mutex> lock(mutex_);
  candidates_ = std::move(candidates);
  candidates_utime_ = utime;
  candidates_in_world_ = in_world_frame;
}

void ViewModel::set_push(const PlannedPush& push) {
  std::lock_guard<std::mutex> lock(mutex_);
  push_ = push;
  has_push_ = true;
}

void ViewModel::observe_state(const StateEntry& state) {
  std::lock_guard<std::mutex> lock(mutex_);
  timeline_.observe(state);
}

void ViewModel::observe_heartbeat(Heartbeat heartbeat, int64_t sender_utime, int64_t receive_utime) {
  std::lock_guard<std::mutex> lock(mutex_);
  // A heartbeat stamped within the replayed log's span came from the log; any other (the viewer's
  // own, a live service's) is judged live.
  constexpr int64_t kMargin = 10'000'000;
  heartbeat.log_time = replaying() && sender_utime >= replay_.start_utime - kMargin &&
                       sender_utime <= replay_.end_utime + kMargin;
  heartbeat.seen_utime = heartbeat.log_time ? sender_utime : receive_utime;
  // On a replay the log's services and the live ones (this viewer, say) may share a name: a row each.
  if (replaying() && !heartbeat.log_time) heartbeat.instance += heartbeat.instance.empty() ? "(live)" : " (live)";
  health_.observe(heartbeat);
}

void ViewModel::add_segmentation(Segmentation segmentation) {
  std::lock_guard<std::mutex> lock(mutex_);
  segmentations_.push_back(std::move(segmentation));
}

bool ViewModel::mask_png(size_t index, std::vector<uint8_t>* png) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (index >= segmentations_.size()) return false;
  *png = segmentations_[index].png;
  return true;
}

void ViewModel::set_replay(const ReplayStatus& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  replay_ = status;
}

void ViewModel::set_processes(std::vector<ProcessRow> processes) {
  std::lock_guard<std::mutex> lock(mutex_);
  processes_ = std::move(processes);
}

json ViewModel::to_json(int64_t now_wall) const {
  std::lock_guard<std::mutex> lock(mutex_);
  json out;
  out["mode"] = replaying() ? "replay" : "live";
  json cameras = json::object();
  for (const auto& [name, cam] : cameras_) {
    json c = {{"seq", cam.frame.seq},
              {"utime", cam.frame.utime},
              {"width", cam.frame.width},
              {"height", cam.frame.height},
              {"fps", frame_rate(cam.recent_utimes)},
              {"lines_utime", cam.lines_utime}};
    c["lines"] = json::array();
    for (const ImageLine& l : cam.lines) c["lines"].push_back(line_json(l));
    if (cam.has_track) {
      json box = json::array();
      for (const auto& corner : cam.track.box) box.push_back({corner[0], corner[1]});
      c["track"] = {{"status", cam.track.status},
                    {"reason", cam.track.reason},
                    {"line", line_json(cam.track.line)},
                    {"box", box},
                    {"utime", cam.track.utime}};
    } else {
      c["track"] = nullptr;
    }
    cameras[name] = c;
  }
  out["cameras"] = cameras;

  json table = {{"candidates", json::array()},
                {"candidates_utime", candidates_utime_},
                {"candidates_frame", candidates_in_world_ ? "world" : "table"},
                {"push", nullptr}};
  for (const Candidate& c : candidates_)
    table["candidates"].push_back({{"position", vec3(c.position)}, {"cluster_size", c.cluster_size}});
  if (has_push_)
    table["push"] = {{"target", vec3(push_.target)},
                     {"direction", vec3(push_.direction)},
                     {"start_distance", push_.start_distance},
                     {"stop_distance", push_.stop_distance},
                     {"utime", push_.utime}};
  out["table"] = table;

  json timeline = json::array();
  for (const StateEntry& s : timeline_.entries()) {
    json e = {{"utime", s.utime},   {"run_id", s.run_id},       {"state", s.state},
              {"attempt", s.attempt}, {"reason", s.reason},     {"segmented", s.segmented},
              {"failed_attempts", s.failed_attempts}};
    e["target"] = s.has_target ? vec3(s.target) : json(nullptr);
    timeline.push_back(e);
  }
  out["supervisor"] = {{"timeline", timeline},
                       {"current", timeline.empty() ? json(nullptr) : timeline.back()}};

  json segmentations = json::array();
  for (size_t i = 0; i < segmentations_.size(); ++i) {
    const Segmentation& s = segmentations_[i];
    segmentations.push_back({{"index", i},
                             {"attempt", s.attempt},
                             {"utime", s.utime},
                             {"pixels", s.pixels},
                             {"width", s.width},
                             {"height", s.height},
                             {"url", "/api/mask/" + std::to_string(i)}});
  }
  out["segmentations"] = segmentations;

  // Live, health is judged on the wall clock; a log's heartbeats at the replay's position.
  json health = json::array();
  for (const HealthRow& row : health_.rows({now_wall, replay_.position_utime}))
    health.push_back({{"name", row.name},
                      {"pid", row.pid},
                      {"state", row.state},
                      {"in_per_s", row.in_per_s},
                      {"out_per_s", row.out_per_s},
                      {"heartbeat_hz", row.heartbeat_hz},
                      {"errors", row.errors},
                      {"last_seen_s", row.last_seen_s},
                      {"alive", row.alive},
                      {"status", row.status}});
  out["health"] = health;

  json processes = json::array();
  for (const ProcessRow& p : processes_)
    processes.push_back({{"name", p.name},
                         {"state", p.state},
                         {"pid", p.pid},
                         {"restarts", p.restarts},
                         {"last_exit_code", p.last_exit_code},
                         {"uptime_s", p.uptime_s},
                         {"restart_in_s", p.restart_in_s},
                         {"log", p.log}});
  out["processes"] = processes;

  if (replaying()) {
    out["replay"] = {{"log", replay_.log},
                     {"state", replay_.state},
                     {"speed", replay_.speed},
                     {"position_utime", replay_.position_utime},
                     {"start_utime", replay_.start_utime},
                     {"end_utime", replay_.end_utime},
                     {"events", replay_.events},
                     {"total_events", replay_.total_events},
                     {"connected", now_wall - replay_.received_wall_utime < 3000000}};
  } else {
    out["replay"] = nullptr;
  }
  return out;
}

}  // namespace nudge::viewer
