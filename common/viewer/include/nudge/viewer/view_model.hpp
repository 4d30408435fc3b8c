#pragma once
// What the viewer's page shows, kept up to date by the viewer service and read by its HTTP
// threads: the latest frame of each camera (JPEG on request) with its symmetry lines and tracked
// line and box, the candidates and the planned push (a top view of the table, thesis fig. 6.6),
// the segmentation masks, the supervisor's timeline, every service's health and the replay's
// position. Thread-safe; no LCM (the service converts messages to these structs).
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "nudge/viewer/health.hpp"
#include "nudge/viewer/timeline.hpp"

namespace nudge::viewer {

// A line in image pixels: the infinite line's ends on the image border and the supported segment.
struct ImageLine {
  double r = 0, theta = 0, votes = 0;
  double x1 = 0, y1 = 0, x2 = 0, y2 = 0;
  double seg_x1 = 0, seg_y1 = 0, seg_x2 = 0, seg_y2 = 0;
};

struct TrackOverlay {
  std::string status, reason;
  ImageLine line;
  double box[4][2] = {};
  int64_t utime = 0;
};

struct Candidate {
  double position[3] = {0, 0, 0};  // metres: the triangulation's table frame, or the arm's world frame
  int cluster_size = 0;
};

// The nudge the supervisor asked the arm for: from P1 (start_distance before the target's axis)
// to P2 (stop_distance before it), along `direction` (thesis fig. 6.3, 6.6).
struct PlannedPush {
  double target[3] = {0, 0, 0};
  double direction[3] = {1, 0, 0};
  double start_distance = 0, stop_distance = 0;
  int64_t utime = 0;
};

struct Segmentation {
  int attempt = 0;
  int64_t utime = 0;
  int pixels = 0;
  int width = 0, height = 0;
  std::vector<uint8_t> png;  // the mask as sent (PNG), served as it is
};

struct ReplayStatus {
  std::string log, state;  // state: "playing", "paused", "finished"
  double speed = 1;
  int64_t position_utime = 0, start_utime = 0, end_utime = 0;
  int64_t events = 0, total_events = 0;
  int64_t received_wall_utime = 0;
};

// One process of the set nudge-launch runs (PROCESS_STATUS).
struct ProcessRow {
  std::string name, state, log;
  int pid = 0, restarts = 0, last_exit_code = -1;
  double uptime_s = 0, restart_in_s = 0;
};

struct JpegFrame {
  int64_t seq = 0, utime = 0;
  int width = 0, height = 0;
  std::vector<uint8_t> jpeg;
};

class ViewModel {
 public:
  explicit ViewModel(double dead_after_s = 2.5, int jpeg_quality = 80);

  // A camera's new frame (8-bit grey or BGR). It is encoded only when a page asks for it.
  void set_frame(const std::string& camera, const cv::Mat& image, int64_t utime);
  // A frame that is JPEG already: served as it is.
  void set_frame_jpeg(const std::string& camera, std::vector<uint8_t> jpeg, int width, int height, int64_t utime);
  // Waits up to timeout_ms for a frame of `camera` newer than after_seq; false when none came
  // (or the camera is unknown).
  bool wait_frame(const std::string& camera, int64_t after_seq, int timeout_ms, JpegFrame* out);

  void set_lines(const std::string& camera, std::vector<ImageLine> lines, int64_t utime);
  void set_track(const std::string& camera, const TrackOverlay& track);
  // `in_world_frame`: converted to the arm's world frame (the planned push's), not the
  // triangulation's table frame they are sent in.
  void set_candidates(std::vector<Candidate> candidates, int64_t utime, bool in_world_frame = false);
  void set_push(const PlannedPush& push);
  void observe_state(const StateEntry& state);
  // sender_utime: the heartbeat's own stamp; receive_utime: when it arrived (wall clock). Live,
  // health goes by arrival; on a replayed log, by the log's stamps against the replay's position.
  void observe_heartbeat(Heartbeat heartbeat, int64_t sender_utime, int64_t receive_utime);
  void add_segmentation(Segmentation segmentation);
  bool mask_png(size_t index, std::vector<uint8_t>* png) const;
  void set_replay(const ReplayStatus& status);
  void set_processes(std::vector<ProcessRow> processes);

  // Everything the page draws, as of wall time `now_wall`.
  nlohmann::json to_json(int64_t now_wall) const;

 private:
  struct Camera {
    cv::Mat image;
    JpegFrame frame;           // frame.jpeg empty until encoded
    std::deque<int64_t> recent_utimes;  // for the frame rate
    std::vector<ImageLine> lines;
    int64_t lines_utime = 0;
    TrackOverlay track;
    bool has_track = false;
  };
  Camera& camera(const std::string& name);
  void note_frame(Camera& cam, int width, int height, int64_t utime);
  bool replaying() const { return replay_.received_wall_utime != 0; }

  const int jpeg_quality_;
  mutable std::mutex mutex_;
  std::condition_variable frame_arrived_;
  std::map<std::string, Camera> cameras_;
  std::vector<Candidate> candidates_;
  int64_t candidates_utime_ = 0;
  bool candidates_in_world_ = false;
  PlannedPush push_;
  bool has_push_ = false;
  StateTimeline timeline_;
  HealthTable health_;
  std::vector<Segmentation> segmentations_;
  ReplayStatus replay_;
  std::vector<ProcessRow> processes_;
};

}  // namespace nudge::viewer
