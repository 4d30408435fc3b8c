#include "nudge/supervisor/report.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <filesystem>
#include <regex>
#include <stdexcept>

#include "nudge/atomic_file.hpp"
#include "nudge/json.hpp"
#include "nudge/segmentation/motion.hpp"

namespace nudge::supervisor {

namespace {

constexpr int kHalfSize = 420;  // mm shown either side of the arm base

cv::Point top_view(const Eigen::Vector3d& world) {
  // World +x towards the camera is drawn downwards, +y to the right: as the right camera sees it.
  return {kHalfSize + static_cast<int>(std::lround(1e3 * world.y())), kHalfSize + static_cast<int>(std::lround(1e3 * world.x()))};
}

void write_png(const std::string& path, const cv::Mat& image) {
  if (image.empty()) return;
  std::vector<uchar> bytes;
  if (!cv::imencode(".png", image, bytes)) throw std::runtime_error(path + ": cannot encode the image");
  write_file_atomically(path, std::string(bytes.begin(), bytes.end()));
}

void write_line(JsonWriter& j, const std::string& key, const std::optional<symmetry::Line>& line) {
  j.key(key);
  if (!line) {
    j.raw("null");
    return;
  }
  j.begin_object().field("r", line->r).field("theta", line->theta).field("votes", line->votes).end_object();
}

void write_point(JsonWriter& j, const std::string& key, const Eigen::Vector3d& p) {
  j.key(key).begin_array().value(p.x()).value(p.y()).value(p.z()).end_array();
}

void write_pixel(JsonWriter& j, const std::string& key, const std::optional<cv::Point2d>& p) {
  j.key(key);
  if (!p) {
    j.raw("null");
    return;
  }
  j.begin_array().value(p->x).value(p->y).end_array();
}

// Thesis ch. 7: recognition, the grasp, the views and the learner's answer.
void write_learning(JsonWriter& j, const Attempt& a) {
  j.key("learning").begin_object();
  j.field("outcome", a.learning).field("reason", a.learning_reason).field("object_key", a.object_key());
  j.field("recognised", a.recognised).field("recognition_reason", a.recognition_reason).field("learned_name", a.learned_name);
  write_line(j, "line_before_left", a.before_line_left);
  write_line(j, "line_after_left", a.after_line_left);
  j.field("mask_pixels_left", a.segmentation_left.mask.empty() ? 0 : cv::countNonZero(a.segmentation_left.mask));
  write_pixel(j, "top_left", a.top[0]);
  write_pixel(j, "top_right", a.top[1]);
  j.key("grasp");
  if (a.grasp) {
    j.begin_object().field("reason", a.grasp->reason);
    write_point(j, "foot", a.grasp->foot);
    write_point(j, "top", a.grasp->top);
    j.field("overestimate_m", a.grasp->overestimate_m).field("grasp_height_m", a.grasp->grasp_height_m).end_object();
  } else {
    j.raw("null");
  }
  j.field("grasp_plan_ms", a.grasp_plan_ms);
  j.field("grasp_plan_cpu_ms", a.grasp_plan_cpu_ms);
  j.key("grasp_plan_stages_ms").begin_array();  // in the order the stages ran
  for (const auto& [stage, ms] : a.grasp_plan_stages_ms) j.begin_object().field("stage", stage).field("ms", ms).end_object();
  j.end_array();
  j.key("expected_grip_width_m");
  if (a.expected_grip_width_m) j.value(*a.expected_grip_width_m); else j.raw("null");
  j.field("grip_opening_m", a.grip_opening_m);
  if (a.put_back_at) write_point(j, "put_back_at", *a.put_back_at);
  j.key("views").begin_array();
  for (const LearnView& v : a.views)
    j.begin_object().field("index", v.index).field("wrist_angle", v.angle).field("utime", static_cast<long long>(v.utime))
        .key("box").begin_array().value(v.box.x).value(v.box.y).value(v.box.width).value(v.box.height).end_array().end_object();
  j.end_array();
  j.end_object();
}

std::filesystem::path attempt_folder(const std::string& directory, int number) {
  char name[32];
  std::snprintf(name, sizeof name, "attempt_%02d", number);
  return std::filesystem::path(directory) / name;
}

}  // namespace

std::string save_view(const std::string& directory, int attempt_number, const LearnView& view) {
  const std::filesystem::path folder = attempt_folder(directory, attempt_number) / "views";
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) throw std::runtime_error(folder.string() + ": cannot create the folder (" + error.message() + ")");
  char name[32];
  std::snprintf(name, sizeof name, "view_%02d.png", view.index);
  write_png((folder / name).string(), view.image);
  return (folder / name).string();
}

cv::Mat draw_workspace(const Attempt& attempt, const ArmSetup& arm, const Eigen::Vector3d& right_camera) {
  cv::Mat picture(2 * kHalfSize, 2 * kHalfSize, CV_8UC3, cv::Scalar(90, 90, 90));
  const cv::Point base = top_view(Eigen::Vector3d::Zero());
  cv::circle(picture, base, static_cast<int>(1e3 * arm.safety.ring_outer), cv::Scalar(255, 255, 255), cv::FILLED, cv::LINE_AA);
  cv::circle(picture, base, static_cast<int>(1e3 * arm.safety.ring_inner), cv::Scalar(90, 90, 90), cv::FILLED, cv::LINE_AA);
  cv::circle(picture, base, 6, cv::Scalar(0, 0, 0), cv::FILLED);
  // The camera: beyond the picture's edge it is drawn on the edge, in its direction.
  Eigen::Vector3d camera = right_camera;
  const double reach = 1e-3 * (kHalfSize - 12);
  if (std::abs(camera.x()) > reach || std::abs(camera.y()) > reach)
    camera *= reach / std::max(std::abs(camera.x()), std::abs(camera.y()));
  const cv::Point c = top_view(camera);
  cv::rectangle(picture, c - cv::Point(10, 6), c + cv::Point(10, 6), cv::Scalar(0, 0, 255), cv::FILLED);
  for (const Candidate& candidate : attempt.candidates) {
    const cv::Point p = top_view(candidate.position);
    cv::circle(picture, p, 20, cv::Scalar(255, 0, 0), 2, cv::LINE_AA);
    cv::circle(picture, p, 3, cv::Scalar(255, 0, 0), cv::FILLED);
  }
  for (const Rejection& r : attempt.rejected) {
    const cv::Point p = top_view(r.position);
    cv::line(picture, p - cv::Point(14, 14), p + cv::Point(14, 14), cv::Scalar(0, 0, 200), 2, cv::LINE_AA);
    cv::line(picture, p - cv::Point(14, -14), p + cv::Point(14, -14), cv::Scalar(0, 0, 200), 2, cv::LINE_AA);
  }
  cv::circle(picture, top_view(attempt.target.position), 26, cv::Scalar(255, 0, 0), 3, cv::LINE_AA);
  const Eigen::Vector3d p1 = attempt.target.position - arm.nudge.start_distance * attempt.direction;
  const Eigen::Vector3d p2 = attempt.target.position - arm.nudge.stop_distance * attempt.direction;
  cv::arrowedLine(picture, top_view(p1), top_view(p2), cv::Scalar(0, 170, 0), 4, cv::LINE_AA, 0, 0.3);
  if (attempt.rest) cv::drawMarker(picture, top_view(*attempt.rest), cv::Scalar(0, 140, 255), cv::MARKER_CROSS, 16, 2);
  char text[96];
  std::snprintf(text, sizeof text, "attempt %d: %s", attempt.number, to_string(attempt.outcome));
  cv::putText(picture, text, {10, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return picture;
}

std::string attempt_json(const Attempt& a) {
  JsonWriter j(9);
  j.begin_object();
  j.field("attempt", a.number).field("outcome", to_string(a.outcome)).field("reason", a.reason);
  j.field("candidate_index", a.target.index).field("candidate_support", a.target.support);
  write_point(j, "target", a.target.position);
  write_point(j, "direction", a.direction);
  j.key("rest");
  if (a.rest) {
    j.begin_array().value(a.rest->x()).value(a.rest->y()).value(a.rest->z()).end_array();
  } else {
    j.raw("null");
  }
  j.key("rest_tilt_deg");
  if (a.rest_tilt_deg) {
    j.value(*a.rest_tilt_deg);
  } else {
    j.raw("null");
  }
  // A push that cleared only an object of height_limit: the object's measured height and what the
  // arm was told (0 when it was not pushed).
  if (a.height_limit > 0) {
    j.field("height_limit_m", a.height_limit);
    j.key("measured_height_m");
    if (a.measured_height) {
      j.value(*a.measured_height);
    } else {
      j.raw("null");
    }
    j.field("pushed_object_height_m", a.pushed_object_height);
  }
  if (a.standing_height > 0) j.field("standing_height_m", a.standing_height);
  if (a.height_from_edges) j.field("height_from_edges_m", *a.height_from_edges);
  if (a.height_from_mask) j.field("height_from_mask_m", *a.height_from_mask);
  if (a.surveyed_at) write_point(j, "surveyed_at", *a.surveyed_at);
  if (a.foot_depth_m) j.field("foot_depth_m", *a.foot_depth_m);
  if (a.replaced) {
    j.key("replaced").begin_object().field("candidate_index", a.replaced->index).field("foot_depth_m", a.replaced_foot_depth_m);
    write_point(j, "position", a.replaced->position);
    j.end_object();
  }
  if (!a.rivals.empty()) {
    j.key("rivals").begin_array();
    for (const auto& [c, depth] : a.rivals) {
      j.begin_object().field("candidate_index", c.index).field("foot_depth_m", depth);
      write_point(j, "position", c.position);
      j.end_object();
    }
    j.end_array();
  }
  if (a.rest_from_mask) write_point(j, "rest_from_mask", *a.rest_from_mask);
  if (a.rest_from_axes) write_point(j, "rest_from_axes", *a.rest_from_axes);
  if (a.mask_front_hidden_behind) write_point(j, "mask_front_hidden_behind", *a.mask_front_hidden_behind);
  if (a.rest_from_still) j.field("rest_from_still", true);
  if (a.weak_after_line_votes) j.field("weak_after_line_votes", *a.weak_after_line_votes);
  j.field("motion_frames", a.motion_frames).field("motion_blocks", a.motion_blocks);
  j.field("tracking_started_s", a.tracking_started / 1e6);
  j.key("track_trace").begin_object();
  for (int camera = 0; camera < 2; ++camera) {
    j.key(camera == 0 ? "left" : "right").begin_array();
    for (const Attempt::TrackSample& t : a.track_trace[camera])
      j.begin_array().value(t.utime / 1e6).value(t.status).value(t.r).value(t.theta).value(t.measured).value(t.holding).end_array();
    j.end_array();
  }
  j.end_object();
  write_line(j, "line_before", a.before_line);
  write_line(j, "line_after", a.after_line);
  j.field("mask_pixels", a.segmentation.mask.empty() ? 0 : cv::countNonZero(a.segmentation.mask));
  j.field("mask_pixels_beside", a.mask_pixels_beside);
  j.field("started_s", a.started / 1e6).field("ended_s", a.ended / 1e6);
  j.key("rejected").begin_array();
  for (const Rejection& r : a.rejected) j.begin_object().field("candidate_index", r.index).field("reason", r.reason).end_object();
  j.end_array();
  if (a.learn || !a.learning.empty() || !a.recognised.empty()) write_learning(j, a);
  j.end_object();
  return j.str();
}

std::string save_attempt(const std::string& directory, const Attempt& attempt, const ArmSetup& arm,
                         const Eigen::Vector3d& right_camera) {
  const std::filesystem::path folder = attempt_folder(directory, attempt.number);
  std::error_code error;
  std::filesystem::create_directories(folder / "stages", error);
  if (error) throw std::runtime_error(folder.string() + ": cannot create the folder (" + error.message() + ")");
  write_png((folder / "before.png").string(), attempt.before);
  write_png((folder / "after.png").string(), attempt.after);
  write_png((folder / "mask.png").string(), attempt.segmentation.mask);
  const cv::Mat& mask = attempt.segmentation.mask;
  if (!mask.empty() && mask.size() == attempt.after.size())
    write_png((folder / "cutout.png").string(), segmentation::cut_out(attempt.after, mask));
  write_png((folder / "workspace.png").string(), draw_workspace(attempt, arm, right_camera));
  for (const auto& [stage, image] : attempt.segmentation.stages) write_png((folder / "stages" / (stage + ".png")).string(), image);
  // Learning (additive): the left stills and segmentation; the views are saved as they are taken.
  write_png((folder / "before_left.png").string(), attempt.before_left);
  write_png((folder / "after_left.png").string(), attempt.after_left);
  write_png((folder / "mask_left.png").string(), attempt.segmentation_left.mask);
  write_png((folder / "recognition_match.png").string(), attempt.recognition_match);
  write_file_atomically((folder / "attempt.json").string(), attempt_json(attempt) + "\n");
  return folder.string();
}

std::string summary_json(const std::string& run_id, int64_t first_command_seq, const Summary& s, const std::vector<std::string>& attempts) {
  JsonWriter j(9);
  j.begin_object();
  j.field("run_id", run_id).field("first_command_seq", static_cast<long long>(first_command_seq)).field("surveys", s.surveys).field("attempts", s.attempts).field("segmented", s.segmented);
  j.field("end_reason", s.end_reason);
  j.key("outcomes").begin_object();
  for (const auto& [outcome, count] : s.outcomes) j.field(outcome, count);
  j.end_object();
  j.field("learned", s.learned);
  j.key("learning").begin_object();
  for (const auto& [outcome, count] : s.learning) j.field(outcome, count);
  j.end_object();
  j.key("known").begin_array();
  for (const std::string& name : s.known) j.value(name);
  j.end_array();
  j.key("last_survey_rejections").begin_object();
  for (const auto& [reason, count] : s.rejections) j.field(reason, count);
  j.end_object();
  j.key("attempt_list").begin_array();
  for (const std::string& a : attempts) j.raw(a);
  j.end_array();
  j.end_object();
  return j.str();
}

std::optional<symmetry::Line> recorded_line(const std::string& attempt_json, const std::string& key) {
  // As write_line writes it: "key":{"r":R,"theta":T,"votes":V} (a number may carry an exponent).
  static const std::string number = "(-?[0-9.]+(?:[eE][-+]?[0-9]+)?)";
  std::smatch m;
  const std::regex pattern("\"" + key + "\":\\{\"r\":" + number + ",\"theta\":" + number + ",\"votes\":" + number);
  if (!std::regex_search(attempt_json, m, pattern)) return std::nullopt;
  symmetry::Line line;
  line.r = std::stod(m[1]);
  line.theta = std::stod(m[2]);
  line.votes = std::stod(m[3]);
  return line;
}

}  // namespace nudge::supervisor
