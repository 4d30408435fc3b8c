// The supervisor's state machine (common/supervisor) on hand-made message sequences: a synthetic
// calibrated scene (a right camera facing the arm across the table, as in the simulated lab), an
// object drawn where it stands, and the arm's answers played by the test.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <mutex>
#include <random>
#include <set>
#include <thread>

#include "nudge/segmentation/motion.hpp"
#include "nudge/supervisor/report.hpp"
#include "nudge/supervisor/supervisor.hpp"

namespace sv = nudge::supervisor;
namespace geo = nudge::geometry;

namespace {

constexpr int64_t kSecond = 1000000;

// A right camera 0.95 m from the arm base looking down at the middle of the workspace ring.
sv::SceneGeometry make_scene() {
  const Eigen::Vector3d camera(0.95, 0.0, 0.45), look_at(0.25, 0.0, 0.05);
  const Eigen::Vector3d z = (look_at - camera).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();  // image right
  const Eigen::Vector3d y = z.cross(x);                                     // image down
  geo::RigidTransform arm_to_right;
  arm_to_right.R.row(0) = x.transpose();
  arm_to_right.R.row(1) = y.transpose();
  arm_to_right.R.row(2) = z.transpose();
  arm_to_right.t = -arm_to_right.R * camera;
  geo::StereoRig rig;
  for (geo::Camera* c : {&rig.left, &rig.right}) c->K << 580, 0, 319.5, 0, 580, 239.5, 0, 0, 1;
  rig.T = Eigen::Vector3d(-0.25, 0, 0.03);
  geo::Plane table;
  table.normal = arm_to_right.R * Eigen::Vector3d::UnitZ();
  table.offset = -table.normal.dot(arm_to_right.t);
  if (table.offset < 0) {
    table.normal = -table.normal;
    table.offset = -table.offset;
  }
  return sv::SceneGeometry(rig, table, arm_to_right.t, arm_to_right);
}

// A segmenter that never finds the object (a push that moved nothing it could cut out).
sv::Segmentation segment_nothing(const cv::Mat&, const cv::Mat&, const nudge::symmetry::Line&, const nudge::symmetry::Line&) {
  sv::Segmentation nothing;
  nothing.error = "segmentation empty";
  return nothing;
}

// A grey box 7 cm wide and 12 cm tall standing at `foot` (world), drawn into a textured background.
// `shapes`: each object's height and half width, when given (0.12 and 0.035 m otherwise).
struct Shape {
  double height = 0.12, half_width = 0.035;
  bool grey = false;  // shades of grey: edges for the detector, no colour for a mask of coloured pixels
};
// The textured table every drawn scene stands on (the same for every image of a size).
cv::Mat drawn_background(cv::Size size) {
  cv::Mat image(size, CV_8UC3);
  cv::RNG rng(7);
  rng.fill(image, cv::RNG::UNIFORM, 90, 110);
  cv::GaussianBlur(image, image, cv::Size(5, 5), 0);
  return image;
}

cv::Mat draw_scene(const sv::SceneGeometry& scene, cv::Size size, const std::vector<Eigen::Vector3d>& objects,
                   bool left = false, const std::vector<Shape>& shapes = {}) {
  cv::Mat image = drawn_background(size);
  const Eigen::Vector3d across = Eigen::Vector3d(0, 1, 0);
  for (size_t k = 0; k < objects.size(); ++k) {
    const Eigen::Vector3d& foot = objects[k];
    const Shape shape = k < shapes.size() ? shapes[k] : Shape{};
    // Nested outlines, darker towards the sides (like a shaded cylinder): its inside changes when
    // it moves, as a real object's does, which block motion and the trackers rely on.
    const double shades[] = {1.0, 0.75, 0.5, 0.25};
    for (int band = 0; band < 4; ++band) {
      const double half = shape.half_width * shades[band];
      const Eigen::Vector3d up(0, 0, shape.height - 0.01 * band);
      const std::vector<Eigen::Vector3d> outline = {foot - half * across, foot + half * across,
                                                    foot + half * across + up, foot - half * across + up};
      std::vector<cv::Point> corners;
      for (const Eigen::Vector3d& corner : outline) {
        const auto p = left ? scene.project_left(corner, size) : scene.project_right(corner, size);
        corners.emplace_back(cvRound(p->x), cvRound(p->y));
      }
      const cv::Scalar colour = shape.grey ? cv::Scalar::all(30 + 45 * band)
                                           : cv::Scalar(200 - 45 * band, 60 + 30 * band, 40 + 40 * band);
      cv::fillConvexPoly(image, corners, colour);
    }
  }
  return image;
}

// The difference of the stills, filled symmetrically about the after line as the motion
// segmentation fills it (fig. 6.7): a mask an upright symmetric object could have.
sv::Segmentation mask_of_difference(const cv::Mat& before, const cv::Mat& after, const nudge::symmetry::Line&,
                                    const nudge::symmetry::Line& after_line) {
  sv::Segmentation s;
  cv::Mat diff, grey;
  cv::absdiff(before, after, diff);
  cv::cvtColor(diff, grey, cv::COLOR_BGR2GRAY);
  cv::threshold(grey, s.mask, 40, 255, cv::THRESH_BINARY);
  s.mask |= nudge::segmentation::mirror_image(s.mask, after_line);
  return s;
}

// The supervisor's defaults, but for the check that a mask's sides follow the after still's edges
// (Config::min_mask_side_edges): mask_of_difference's masks span the object's places before and
// after the push, beyond its outline in the after still. The check's own test turns it on.
sv::Config drawn_config() {
  sv::Config config;
  config.min_mask_side_edges = 0;
  return config;
}

// `line` turned by `degrees` about the middle of its support segment (a line a label leans).
nudge::symmetry::Line leaning(const nudge::symmetry::Line& line, double degrees, cv::Size size) {
  const cv::Point2d middle = 0.5 * (line.seg1 + line.seg2), d = line.seg2 - line.seg1;
  const double turn = degrees * M_PI / 180;
  const cv::Point2d turned(d.x * std::cos(turn) - d.y * std::sin(turn), d.x * std::sin(turn) + d.y * std::cos(turn));
  nudge::symmetry::Line out = sv::line_through(middle - 0.5 * turned, middle + 0.5 * turned, size);
  out.seg1 = middle - 0.5 * turned;
  out.seg2 = middle + 0.5 * turned;
  return out;
}

template <typename T>
std::vector<T> outputs_of(const std::vector<sv::Output>& outputs) {
  std::vector<T> found;
  for (const sv::Output& o : outputs)
    if (const T* t = std::get_if<T>(&o)) found.push_back(*t);
  return found;
}

nudge::robot::JointVector arm_state_joints() {
  return sv::ArmSetup{}.home();  // where the arm service parks
}

sv::ArmStatus arm(sv::ArmStatus::Motion motion, int64_t seq, const std::string& error = "") {
  sv::ArmStatus a;
  a.motion = motion;
  a.command_seq = seq;
  a.last_error = error;
  a.joints = arm_state_joints();
  return a;
}

// The right camera's mask (255 = object) of an upright cylinder standing at `foot`: the convex hull
// of its two rims, projected (a cylinder's silhouette is convex).
cv::Mat cylinder_mask(const sv::SceneGeometry& scene, cv::Size size, const Eigen::Vector3d& foot, double radius, double height,
                      bool left = false) {
  std::vector<cv::Point> points;
  for (double z : {0.0, height})
    for (int k = 0; k < 72; ++k) {
      const double a = k * M_PI / 36;
      const Eigen::Vector3d rim = foot + Eigen::Vector3d(radius * std::cos(a), radius * std::sin(a), z);
      const auto p = left ? scene.project_left(rim, size) : scene.project_right(rim, size);
      points.emplace_back(cvRound(p->x), cvRound(p->y));
    }
  std::vector<cv::Point> hull;
  cv::convexHull(points, hull);
  cv::Mat mask = cv::Mat::zeros(size, CV_8U);
  cv::fillConvexPoly(mask, hull, cv::Scalar(255));
  return mask;
}

class SupervisorTest : public ::testing::Test {
 protected:
  SupervisorTest() : scene_(make_scene()) {}

  sv::Supervisor make(sv::Config config = drawn_config()) {
    return sv::Supervisor(config, scene_, sv::ArmSetup{}, mask_of_difference);
  }

  // Starts a run and answers its first survey with `candidates` (world positions).
  std::vector<sv::Output> start_with(sv::Supervisor& s, const std::vector<Eigen::Vector3d>& candidates) {
    s.start(now_, 100);
    s.on_services({}, now_);
    return answer_survey(s, candidates);
  }
  // After a nudge the arm parks first (HOME); the test's arm reports it parked.
  void park(sv::Supervisor& s) {
    if (s.state() != sv::State::Home) return;
    now_ += kSecond;
    s.on_arm_state(arm(sv::ArmStatus::Motion::Done, s.awaited_arm_seq()), now_);
  }
  std::vector<sv::Output> answer_survey(sv::Supervisor& s, const std::vector<Eigen::Vector3d>& candidates) {
    park(s);
    s.take_outputs();
    EXPECT_EQ(s.state(), sv::State::FindCandidates);
    now_ += 3 * kSecond;
    std::vector<sv::Candidate> list;
    for (size_t i = 0; i < candidates.size(); ++i) list.push_back({static_cast<int>(i), candidates[i], 20});
    s.on_candidates(list, now_, now_);
    return s.take_outputs();
  }
  // `frames` stereo pairs of survey lines, taken after the survey began, that show `object`'s axis.
  void hear_survey_lines(sv::Supervisor& s, const Eigen::Vector3d& object, int frames) {
    const auto line_left = scene_.left_axis_line(object, 0.25, {640, 480});
    const auto line_right = scene_.right_axis_line(object, 0.25, {640, 480});
    ASSERT_TRUE(line_left && line_right);
    for (int i = 0; i < frames; ++i) {
      s.on_lines(true, {*line_left}, now_ + kSecond / 10, now_ + kSecond / 5);
      s.on_lines(false, {*line_right}, now_ + kSecond / 10, now_ + kSecond / 5);
    }
  }
  // A stereo pair of frames of `objects`.
  void show(sv::Supervisor& s, const std::vector<Eigen::Vector3d>& objects) {
    s.on_left_frame(draw_scene(scene_, {640, 480}, objects, true), now_);
    s.on_right_frame(draw_scene(scene_, {640, 480}, objects), now_);
  }
  // Frames of the object standing, then sliding from `from` to `to` while the arm reports MOVING,
  // then DONE.
  void play_nudge(sv::Supervisor& s, int64_t seq, const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                  const std::vector<Eigen::Vector3d>& others = {}) {
    s.on_arm_state(arm(sv::ArmStatus::Motion::Moving, seq), now_);
    for (int i = -3; i <= 15; ++i) {
      std::vector<Eigen::Vector3d> objects = others;
      objects.push_back(from + (to - from) * (std::clamp(i, 0, 15) / 15.0));
      now_ += kSecond / 10;
      show(s, objects);
    }
    now_ += kSecond / 10;
    s.on_arm_state(arm(sv::ArmStatus::Motion::Done, seq), now_);
    last_objects_ = others;
    last_objects_.push_back(to);
  }
  // The object at rest for two seconds (frames and, for the loop without trackers, upright AXES).
  std::vector<sv::Output> slide_without_symmetry(sv::Supervisor& s);
  std::optional<sv::NudgeCommand> nudge_of_rivals_on_one_right_line(const sv::Config& config, double behind_m,
                                                                    const std::optional<Eigen::Vector3d>& third = std::nullopt);
  Eigen::Vector3d nudged_of_rivals_on_one_right_line(const sv::Config& config, double behind_m) {
    const auto nudge = nudge_of_rivals_on_one_right_line(config, behind_m);
    return nudge ? nudge->target : Eigen::Vector3d::Zero();
  }
  std::pair<std::optional<sv::NudgeCommand>, std::string> nudge_beside_an_unpaired_object(const sv::Config& config,
                                                                                          const Eigen::Vector3d& beside);
  // A run started on `object` alone, its before still taken (drawn as `shape`): the nudge the
  // supervisor commands.
  sv::NudgeCommand nudge_command_for(sv::Supervisor& s, const Eigen::Vector3d& object, const Shape& shape = {}) {
    start_with(s, {object});
    s.on_right_still(draw_scene(scene_, {1280, 960}, {object}, false, {shape}), now_, now_);
    return outputs_of<sv::NudgeCommand>(s.take_outputs()).at(0);
  }
  // A run started on `object` whose before still also shows a neighbour `neighbour_travel_m` along
  // the push the supervisor will command (found with a probe run on the same config): the nudge it
  // commands, and where the neighbour stands.
  std::pair<sv::NudgeCommand, Eigen::Vector3d> nudge_command_with_neighbour_along(sv::Supervisor& s, const sv::Config& config,
                                                                                  const Eigen::Vector3d& object,
                                                                                  double neighbour_travel_m) {
    sv::Supervisor probe = make(config);
    const Eigen::Vector3d direction = nudge_command_for(probe, object).direction;
    const Eigen::Vector3d neighbour = object + neighbour_travel_m * direction;
    start_with(s, {object});
    s.on_right_still(draw_scene(scene_, {1280, 960}, {object, neighbour}), now_, now_);
    const sv::NudgeCommand nudge = outputs_of<sv::NudgeCommand>(s.take_outputs()).at(0);
    EXPECT_LT((nudge.direction - direction).norm(), 1e-9);
    return {nudge, neighbour};
  }
  // A run's first attempt on `object` up to the after still: surveyed, the before still taken,
  // nudged 3 cm, settled and parked. Returns where it rests.
  Eigen::Vector3d nudge_and_park(sv::Supervisor& s, const Eigen::Vector3d& object) {
    const sv::NudgeCommand nudge = nudge_command_for(s, object);
    const Eigen::Vector3d rest = object + 0.03 * nudge.direction;
    play_nudge(s, nudge.seq, object, rest);
    settle_with_axes(s, {rest});
    park(s);
    return rest;
  }
  // The object at (0.28, -0.05) nudged and pushed 3 cm; the arm is done and the supervisor waits
  // for it to settle. Where it rests.
  Eigen::Vector3d push_until_settling(sv::Supervisor& s) {
    const Eigen::Vector3d object(0.28, -0.05, 0);
    const sv::NudgeCommand nudge = nudge_command_for(s, object);
    const Eigen::Vector3d rest = object + 0.03 * nudge.direction;
    play_nudge(s, nudge.seq, object, rest);
    return rest;
  }

  // Two seconds of settled frames, and on while the supervisor settles longer (too few axes).
  void settle_with_axes(sv::Supervisor& s, const std::vector<Eigen::Vector3d>& feet, double tilt = 0.02) {
    for (int i = 1; i <= 20 || (s.state() == sv::State::Track && i <= 100); ++i) {
      now_ += kSecond / 10;
      if (s.state() == sv::State::Track) show(s, last_objects_);
      std::vector<sv::Axis> axes;
      for (const auto& f : feet) axes.push_back({f, tilt});
      s.on_axes(axes, now_, now_);
      s.on_time(now_);
    }
  }

  // One object at (0.28, -0.05) nudged 3 cm; the settled axes stand at the given distances behind
  // its rest along the right camera's ray. What the attempt ended with after the after still.
  struct NudgedAlongRay {
    Eigen::Vector3d rest;
    sv::State state;
    std::string reason;
    std::vector<sv::AttemptEnded> ended;
  };
  NudgedAlongRay nudge_and_settle_along_ray(const std::vector<double>& axes_behind_m) {
    sv::Supervisor s = make();
    const Eigen::Vector3d object(0.28, -0.05, 0);
    const sv::NudgeCommand nudge = nudge_command_for(s, object);
    NudgedAlongRay run;
    run.rest = object + 0.03 * nudge.direction;
    const Eigen::Vector3d ray = along_ray(run.rest);
    play_nudge(s, nudge.seq, object, run.rest);
    std::vector<Eigen::Vector3d> feet;
    for (double behind : axes_behind_m) feet.push_back(run.rest + behind * ray);
    settle_with_axes(s, feet);
    park(s);
    run.state = s.state();
    run.reason = s.report().reason;
    if (run.state != sv::State::SnapshotAfter) return run;
    s.on_right_still(draw_scene(scene_, {1280, 960}, {run.rest}), now_, now_);
    run.ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
    return run;
  }

  // Parks the arm and shows the after still with the object standing at `object`: the attempt
  // that ended, or nothing (a failure).
  std::shared_ptr<const sv::Attempt> park_and_show_after_still(sv::Supervisor& s, const Eigen::Vector3d& object) {
    return park_and_show_after_still_of(s, {object});
  }
  std::shared_ptr<const sv::Attempt> park_and_show_after_still_of(sv::Supervisor& s, const std::vector<Eigen::Vector3d>& objects,
                                                                  const std::vector<Shape>& shapes = {}) {
    park(s);
    if (s.state() != sv::State::SnapshotAfter) {
      ADD_FAILURE() << "no after still asked for: " << s.report().reason;
      return nullptr;
    }
    s.on_right_still(draw_scene(scene_, {1280, 960}, objects, false, shapes), now_, now_);
    const auto ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
    if (ended.size() != 1u) {
      ADD_FAILURE() << ended.size() << " attempts ended";
      return nullptr;
    }
    return ended[0].attempt;
  }
  // One attempt on the object at (0.28, -0.05) whose stills `segment` segments: how it ended.
  sv::Attempt attempt_segmented_by(const sv::SegmentFunction& segment, const sv::Config& config = drawn_config()) {
    sv::Supervisor s(config, scene_, sv::ArmSetup{}, segment);
    const Eigen::Vector3d rest = nudge_and_park(s, Eigen::Vector3d(0.28, -0.05, 0));
    EXPECT_EQ(s.state(), sv::State::SnapshotAfter);
    s.on_right_still(draw_scene(scene_, {1280, 960}, {rest}), now_, now_);
    const auto ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
    if (ended.size() != 1u) {
      ADD_FAILURE() << ended.size() << " attempts ended";
      return {};
    }
    return *ended[0].attempt;
  }
  // The right camera's viewing direction along the table at `point`.
  Eigen::Vector3d along_ray(const Eigen::Vector3d& point) const {
    Eigen::Vector3d ray = point - scene_.right_camera_in_world();
    ray.z() = 0;
    return ray.normalized();
  }

  sv::SceneGeometry scene_;
  int64_t now_ = 50 * kSecond;
  std::vector<Eigen::Vector3d> last_objects_;
};

}  // namespace

TEST(SceneGeometry, ProjectsAVerticalAxisToAnUprightLineAndBack) {
  const sv::SceneGeometry scene = make_scene();
  const Eigen::Vector3d foot(0.25, 0.05, 0);
  const auto line = scene.right_axis_line(foot, 0.2, {640, 480});
  ASSERT_TRUE(line);
  EXPECT_LT(std::abs(line->theta), 0.2);  // nearly vertical in the image
  const auto p = scene.project_right(foot + Eigen::Vector3d(0, 0, 0.1), {640, 480});
  EXPECT_NEAR(sv::signed_distance(*line, *p, {640, 480}), 0.0, 1e-6);
  // World +y lies to the image's right; the stills are the same camera at twice the resolution.
  EXPECT_GT(scene.project_right(foot + Eigen::Vector3d(0, 0.05, 0), {640, 480})->x, scene.project_right(foot, {640, 480})->x);
  const auto small = scene.project_right(foot, {640, 480}), large = scene.project_right(foot, {1280, 960});
  EXPECT_NEAR(large->x, 2 * small->x + 0.5, 1e-9);
  // Table frame of the triangulation service -> world: the arm base's foot is the origin of both.
  EXPECT_NEAR(scene.table_to_world(Eigen::Vector3d::Zero()).norm(), 0.0, 1e-9);
  EXPECT_NEAR(scene.table_to_world(Eigen::Vector3d(0.1, 0, 0)).norm(), 0.1, 1e-9);
  EXPECT_NEAR(scene.table_to_world(Eigen::Vector3d(0.1, 0.2, 0)).z(), 0.0, 1e-9);
}

TEST(Targets, PushPathConflictsOnlyWithCandidatesInTheSweep) {
  sv::ArmSetup arm;
  sv::TargetParams params;
  const Eigen::Vector3d target(0.25, 0, 0), direction(0, 1, 0);
  using Kind = sv::PushConflict::Kind;
  EXPECT_EQ(sv::push_conflict(target, direction, Eigen::Vector3d(0.25, 0.06, 0), arm, params).kind, Kind::Slide);  // ahead
  EXPECT_EQ(sv::push_conflict(target, direction, Eigen::Vector3d(0.25, -0.10, 0), arm, params).kind, Kind::Pad);   // where the pad descends
  EXPECT_EQ(sv::push_conflict(target, direction, Eigen::Vector3d(0.21, -0.03, 0), arm, params).kind, Kind::Pad);   // beside the pad's path
  // 7 cm beside the pad's path: the 8 cm wide pad's edge passes 3 cm from the axis of an object
  // up to 4.5 cm in radius (with a 4 cm pad this was no conflict).
  EXPECT_EQ(sv::push_conflict(target, direction, Eigen::Vector3d(0.32, -0.06, 0), arm, params).kind, Kind::Pad);
  sv::TargetParams narrow = params;
  narrow.pad_half_width = 0.02;
  EXPECT_EQ(sv::push_conflict(target, direction, Eigen::Vector3d(0.32, -0.06, 0), arm, narrow).kind, Kind::None);
  EXPECT_EQ(sv::push_conflict(target, direction, Eigen::Vector3d(0.35, 0.0, 0), arm, params).kind, Kind::None);    // beside
  EXPECT_EQ(sv::push_conflict(target, direction, Eigen::Vector3d(0.25, 0.30, 0), arm, params).kind, Kind::None);   // far ahead
}

TEST(Targets, NearestTheCameraFirstAndEveryPassOverHasAReason) {
  const sv::SceneGeometry scene = make_scene();
  const sv::ArmSetup arm;
  const std::vector<sv::Candidate> candidates = {{0, Eigen::Vector3d(0.20, 0.12, 0), 9},
                                                 {1, Eigen::Vector3d(0.30, -0.10, 0), 9},
                                                 {2, Eigen::Vector3d(0.62, 0.0, 0), 9},   // beyond the ring
                                                 {3, Eigen::Vector3d(0.05, 0.0, 0), 9}};  // inside it
  // The arm's links leaned over candidate 0 would pass within reach of a 0.25 m object there, and
  // the push would be turned: here the links are not checked (TheArmsLinksKeepClear... is).
  sv::TargetParams links_unchecked;
  links_unchecked.obstacle_height = 0;
  const auto choice = sv::choose_target(candidates, {}, scene.right_camera_in_world(), arm,
                                        arm_state_joints(), links_unchecked);
  ASSERT_TRUE(choice.found);
  EXPECT_EQ(choice.target.index, 1);  // the nearest reachable one
  ASSERT_EQ(choice.rejected.size(), 1u);  // only the one nearer the camera is passed over
  EXPECT_EQ(choice.rejected[0].index, 2);
  EXPECT_NE(choice.rejected[0].reason.find("out of reach"), std::string::npos) << choice.rejected[0].reason;
  // Perpendicular to the camera's ray, horizontal.
  const Eigen::Vector3d ray = (choice.target.position - scene.right_camera_in_world()).normalized();
  EXPECT_NEAR(choice.direction.dot(Eigen::Vector3d(ray.x(), ray.y(), 0).normalized()), 0.0, 1e-6);
  EXPECT_NEAR(choice.direction.z(), 0.0, 1e-12);
  // Explored places are skipped; with everything explored or unreachable nothing is chosen.
  const auto rest = sv::choose_target(candidates, sv::History{{candidates[0].position, candidates[1].position}, {}, {}, {}, {}},
                                      scene.right_camera_in_world(), arm, arm_state_joints(), sv::TargetParams{});
  EXPECT_FALSE(rest.found);
  EXPECT_EQ(rest.rejected.size(), 4u);
  // Explored objects standing on the pad's way either side (no candidates: later surveys leave
  // their lines out) block both pushes as candidates would.
  const double pad = 0.5 * (arm.nudge.start_distance + arm.nudge.stop_distance);
  sv::History blocked;
  blocked.standing = {sv::ExploredObject(choice.target.position - pad * choice.direction),
                      sv::ExploredObject(choice.target.position + pad * choice.direction)};
  const auto around = sv::choose_target({candidates[1]}, blocked, scene.right_camera_in_world(), arm, arm_state_joints(),
                                        sv::TargetParams{});
  EXPECT_FALSE(around.found);
  ASSERT_EQ(around.rejected.size(), 1u);
  EXPECT_NE(around.rejected[0].reason.find("the pad would touch the explored object at"), std::string::npos) << around.rejected[0].reason;
}

// The least gap between the arm's links, along the whole command the arm service would run for
// `choice` from `seed` and the way home after it, and an object of the expected size standing at `other`.
double least_link_gap(const sv::TargetChoice& choice, const sv::ArmSetup& arm, const nudge::robot::JointVector& seed,
                      const Eigen::Vector3d& other, const sv::TargetParams& params, double height = 0) {
  nudge::robot::Command command;
  command.kind = nudge::robot::CommandKind::Nudge;
  command.target_position = choice.target.position;
  command.direction = choice.direction;
  command.object_height = choice.height_limit;
  const auto plan = nudge::robot::plan_command(arm.planner(), command, seed);
  EXPECT_TRUE(plan.ok()) << plan.reason;
  std::vector<nudge::robot::JointVector> path = {seed};
  for (const auto& step : plan.steps) {
    if (step.kind == nudge::robot::MotionStep::Kind::Move) path.push_back(step.goal);
    path.insert(path.end(), step.path.begin(), step.path.end());
  }
  path.push_back(arm.home());  // parking after the push
  const nudge::robot::StandingObject object{arm.point_to_base(other), params.object_radius, height > 0 ? height : params.obstacle_height};
  return nudge::robot::least_link_gap_along(arm.model, arm.safety_config(), object, path);
}

// Pairs of objects 12 cm apart over the workspace ring: the first 0.18-0.32 m from the base within
// 60 deg of straight ahead, the second at six bearings around it.
void for_each_pair_over_the_ring(const std::function<void(const Eigen::Vector3d&, const Eigen::Vector3d&)>& visit) {
  for (double radius = 0.18; radius <= 0.32; radius += 0.07)
    for (double bearing = -60; bearing <= 60; bearing += 30)
      for (double turn = 0; turn < 360; turn += 60) {
        const double b = bearing * M_PI / 180, t = turn * M_PI / 180;
        const Eigen::Vector3d first(radius * std::cos(b), radius * std::sin(b), 0);
        visit(first, first + 0.12 * Eigen::Vector3d(std::cos(t), std::sin(t), 0));
      }
}

// A choice the strict rule made (no conflict tolerated, so no note saying what it risks).
bool chosen_strictly(const sv::TargetChoice& c) { return c.found && c.note.find("no clear push left") == std::string::npos; }

// TargetParams::spare_doubtful: a candidate seen in too few of the survey's frames to be an
// obstacle (stereo agreement under min_stereo_agreement) may still be a real object (development2
// hm1: a cup seen in 28 % of the frames, knocked over by the pad of a neighbour's push). Where the
// target's first push would bring the pad down beside it, the target is pushed another way that
// keeps clear of it; with the rule off, or for a candidate never seen (under min_nudge_agreement),
// or when no push keeps clear of every doubtful one, the push is as without them. The order of the
// targets does not change.
TEST(Targets, APushKeepsClearOfDoubtfulCandidatesWhenOneCan) {
  const sv::SceneGeometry scene = make_scene();
  const sv::ArmSetup arm;
  const sv::Candidate target{1, Eigen::Vector3d(0.25, 0.0, 0), 9};  // both ways across the view plan
  sv::TargetParams off;
  off.spare_doubtful = false;
  const auto first = sv::choose_target({target}, {}, scene.right_camera_in_world(), arm, arm_state_joints(), off);
  ASSERT_TRUE(chosen_strictly(first)) << first.note;
  const double pad = 0.5 * (arm.nudge.start_distance + arm.nudge.stop_distance);
  auto doubtful_at = [&](const Eigen::Vector3d& place, double agreement) {
    sv::Candidate c{7, place, 4};
    c.stereo_agreement = agreement;
    return c;
  };
  // Just behind where the pad comes down (P1 is start_distance before the axis), 3 cm to one side:
  // the pad would touch it, while the other way's pushed object stops short of it.
  const Eigen::Vector3d behind = target.position - (arm.nudge.start_distance + 0.03) * first.direction -
                                 0.03 * Eigen::Vector3d(-first.direction.y(), first.direction.x(), 0);
  const std::vector<sv::Candidate> candidates = {target, doubtful_at(behind, 0.28)};
  ASSERT_EQ(sv::push_conflict(target.position, first.direction, behind, arm, sv::TargetParams{}).kind, sv::PushConflict::Kind::Pad);

  const auto spared = sv::choose_target(candidates, {}, scene.right_camera_in_world(), arm, arm_state_joints(), sv::TargetParams{});
  ASSERT_TRUE(chosen_strictly(spared)) << spared.note;
  EXPECT_EQ(spared.target.index, 1);  // the order stands: the doubtful one still goes last
  EXPECT_LT(spared.direction.dot(first.direction), 0.9) << "pushed the same way, the pad beside the doubtful candidate";
  EXPECT_FALSE(sv::push_conflict(target.position, spared.direction, behind, arm, sv::TargetParams{}));
  EXPECT_GE(least_link_gap(spared, arm, arm_state_joints(), behind, sv::TargetParams{}), arm.nudge.link_clearance);

  const auto unspared = sv::choose_target(candidates, {}, scene.right_camera_in_world(), arm, arm_state_joints(), off);
  ASSERT_TRUE(unspared.found);
  EXPECT_EQ(unspared.target.index, 1);
  EXPECT_NEAR(unspared.direction.dot(first.direction), 1.0, 1e-9) << "with the rule off a doubtful candidate is no obstacle";

  const auto never_seen = sv::choose_target({target, doubtful_at(behind, 0.0)}, {}, scene.right_camera_in_world(), arm,
                                            arm_state_joints(), sv::TargetParams{});
  ASSERT_TRUE(never_seen.found);
  EXPECT_NEAR(never_seen.direction.dot(first.direction), 1.0, 1e-9) << "a candidate never seen by both cameras is no object to keep clear of";

  // Doubtful candidates where the pad comes down for either way across the view and for every
  // turned push: nothing keeps clear of them all, so the push is the one chosen without them.
  std::vector<sv::Candidate> everywhere = {target};
  for (int k = 0; k < 12; ++k) {
    const double a = k * M_PI / 6;
    everywhere.push_back(doubtful_at(target.position + pad * Eigen::Vector3d(std::cos(a), std::sin(a), 0), 0.28));
    everywhere.back().index = 10 + k;
  }
  sv::TargetParams no_waiting;  // the target waits for such neighbours by default (next test)
  no_waiting.defer_for_doubtful = false;
  const auto crowded = sv::choose_target(everywhere, {}, scene.right_camera_in_world(), arm, arm_state_joints(), no_waiting);
  ASSERT_TRUE(crowded.found);
  EXPECT_EQ(crowded.target.index, 1);
  EXPECT_NEAR(crowded.direction.dot(first.direction), 1.0, 1e-9);
}

// TargetParams::defer_for_doubtful: a candidate every push of which would endanger a doubtful
// candidate not yet nudged waits, and a doubtful one is nudged first; once they are explored (or
// with the rule off) the candidate's push is chosen as without them.
TEST(Targets, ACandidateWaitsForTheDoubtfulOnesEveryPushWouldEndanger) {
  const sv::SceneGeometry scene = make_scene();
  const sv::ArmSetup arm;
  const Eigen::Vector3d camera = scene.right_camera_in_world();
  sv::TargetParams params;  // the two pushes across the view only: two neighbours block them both
  params.obstacle_height = 0;  // the links are not what this is about
  params.max_push_turn_deg = 0;
  const sv::Candidate target{1, Eigen::Vector3d(0.20, 0.0, 0), 9};
  const auto alone = sv::choose_target({target}, {}, camera, arm, arm_state_joints(), params);
  ASSERT_TRUE(chosen_strictly(alone)) << alone.note;
  // A doubtful neighbour just beyond where the pad comes down, either way across the view; each
  // far enough from the target to be pushed towards it without sliding into it.
  const double apart = arm.nudge.start_distance + 0.035;
  std::vector<sv::Candidate> candidates = {target};
  sv::History explored;
  for (double side : {-1.0, 1.0}) {
    sv::Candidate c{candidates.size() == 1 ? 10 : 11, target.position + side * apart * alone.direction, 4};
    c.stereo_agreement = 0.28;
    candidates.push_back(c);
    explored.phantoms.push_back(c.position);
    ASSERT_EQ(sv::push_conflict(target.position, -side * alone.direction, c.position, arm, params).kind,
              sv::PushConflict::Kind::Pad);
  }
  const auto waited = sv::choose_target(candidates, {}, camera, arm, arm_state_joints(), params);
  ASSERT_TRUE(chosen_strictly(waited)) << waited.note;
  EXPECT_GE(waited.target.index, 10) << "a doubtful neighbour goes first";
  const auto note = std::find_if(waited.rejected.begin(), waited.rejected.end(), [](const sv::Rejection& r) { return r.index == 1; });
  ASSERT_NE(note, waited.rejected.end()) << "the waiting candidate's reason is noted";
  EXPECT_NE(note->reason.find("doubtful candidate not yet nudged"), std::string::npos) << note->reason;
  EXPECT_FALSE(sv::push_conflict(waited.target.position, waited.direction, target.position, arm, params))
      << "its push keeps clear of the waiting candidate, which counts as an object";

  sv::TargetParams off = params;
  off.defer_for_doubtful = false;
  const auto in_order = sv::choose_target(candidates, {}, camera, arm, arm_state_joints(), off);
  ASSERT_TRUE(in_order.found);
  EXPECT_EQ(in_order.target.index, 1);

  // Both neighbours nudged (phantoms): nothing left to wait for.
  const auto after = sv::choose_target(candidates, explored, camera, arm, arm_state_joints(), params);
  ASSERT_TRUE(after.found);
  EXPECT_EQ(after.target.index, 1);
  EXPECT_NEAR(after.direction.dot(in_order.direction), 1.0, 1e-9);

  // The neighbours never seen by both cameras: not doubtful, no waiting.
  std::vector<sv::Candidate> unseen = candidates;
  for (size_t k = 1; k < unseen.size(); ++k) unseen[k].stereo_agreement = 0.0;
  const auto not_doubtful = sv::choose_target(unseen, {}, camera, arm, arm_state_joints(), params);
  ASSERT_TRUE(not_doubtful.found);
  EXPECT_EQ(not_doubtful.target.index, 1);
}

// An explored object is kept clear of as tall as the stills measured it: a short one frees pushes
// whose links pass over it, a tall one is cleared in full. Unmeasured, it is the tallest expected.
// Beyond the thesis' order (nearest the right camera first): with TargetParams::Order::MostSupport
// the candidate with the most intersects goes first, nearest first among equals; candidates both
// cameras did not see still go last.
TEST(Targets, MostSupportFirstWhenAskedNearestAmongEquals) {
  const sv::SceneGeometry scene = make_scene();
  const sv::ArmSetup arm;
  sv::TargetParams params;
  params.obstacle_height = 0;  // the links are not what this is about
  // 0: nearer the camera, fewer intersects (a phantom's); 1: farther, the most; 2: as strong as 1,
  // nearer still, but seen by one camera only.
  std::vector<sv::Candidate> candidates = {{0, Eigen::Vector3d(0.30, -0.10, 0), 12},
                                           {1, Eigen::Vector3d(0.20, 0.12, 0), 25},
                                           {2, Eigen::Vector3d(0.31, 0.12, 0), 25, 0.2}};
  const Eigen::Vector3d camera = scene.right_camera_in_world();
  auto first = [&](const sv::TargetParams& p) {
    const auto choice = sv::choose_target(candidates, {}, camera, arm, arm_state_joints(), p);
    EXPECT_TRUE(choice.found);
    return choice.target.index;
  };
  EXPECT_EQ(first(params), 0);  // nearest the camera (the thesis)
  params.order = sv::TargetParams::Order::MostSupport;
  EXPECT_EQ(first(params), 1);
  candidates[0].support = 25;  // equals: the nearest again
  EXPECT_EQ(first(params), 0);
}

TEST(Targets, AnExploredObjectIsKeptClearOfAsTallAsItWasMeasured) {
  const sv::SceneGeometry scene = make_scene();
  const sv::ArmSetup arm;
  const sv::TargetParams params;
  int freed = 0, strict_short = 0, strict_tall = 0;
  for_each_pair_over_the_ring([&](const Eigen::Vector3d& first, const Eigen::Vector3d& second) {
    auto choose = [&](double height) {
      sv::History explored;
      explored.standing = {sv::ExploredObject(second, height)};
      return sv::choose_target({{0, first, 9}}, explored, scene.right_camera_in_world(), arm, arm_state_joints(), params);
    };
    const auto unmeasured = choose(0), short_one = choose(0.10), tall_one = choose(0.32);
    if (chosen_strictly(short_one)) {
      ++strict_short;
      EXPECT_GE(least_link_gap(short_one, arm, arm_state_joints(), second, params, 0.10), arm.nudge.link_clearance);
      freed += !chosen_strictly(unmeasured);
    }
    if (chosen_strictly(tall_one)) {
      ++strict_tall;
      EXPECT_GE(least_link_gap(tall_one, arm, arm_state_joints(), second, params, 0.32), arm.nudge.link_clearance)
          << sv::millimetres(first) << " beside the explored " << sv::millimetres(second);
    }
    // What clears the tallest expected clears a shorter object too.
    if (chosen_strictly(unmeasured)) {
      EXPECT_TRUE(chosen_strictly(short_one)) << sv::millimetres(first) << " beside " << sv::millimetres(second);
    }
  });
  EXPECT_GT(strict_short, 20);
  EXPECT_GT(strict_tall, 10);
  EXPECT_GT(freed, 0) << "measured short, some pushes pass over it that the tallest expected would refuse";
}

TEST(Targets, TheArmsLinksKeepClearOfTheOtherCandidatesWheneverSomePushDoes) {
  const sv::SceneGeometry scene = make_scene();
  const sv::ArmSetup arm;
  const sv::TargetParams params;
  sv::TargetParams unchecked;
  unchecked.obstacle_height = 0;
  int strict = 0, mended = 0, beside_clear = 0, known_spared = 0;
  for_each_pair_over_the_ring([&](const Eigen::Vector3d& first, const Eigen::Vector3d& second) {
    const std::vector<sv::Candidate> candidates = {{0, first, 9}, {1, second, 9}};
    // An object explored and standing there is kept clear of as a candidate is, and more: the
    // links never sweep it, not even when no push is clear (a candidate may be a phantom; an
    // explored object is real, often learned and put back).
    sv::History explored;
    explored.standing = {second};
    const auto beside = sv::choose_target({candidates[0]}, explored, scene.right_camera_in_world(), arm, arm_state_joints(), params);
    if (chosen_strictly(beside)) ++beside_clear;
    if (beside.found) {
      EXPECT_GE(least_link_gap(beside, arm, arm_state_joints(), second, params), arm.nudge.link_clearance)
          << sv::millimetres(first) << " beside the explored " << sv::millimetres(second) << ": " << beside.note;
    }
    // Something only one camera's lines show there may be nothing: its links conflict is taken last.
    sv::History sighted;
    sighted.sighted = {second};
    const auto beside_unknown = sv::choose_target({candidates[0]}, sighted, scene.right_camera_in_world(), arm, arm_state_joints(), params);
    if (!beside.found && beside_unknown.found && beside_unknown.note.find("the arm's links would pass within") != std::string::npos)
      ++known_spared;
    const auto choice = sv::choose_target(candidates, {}, scene.right_camera_in_world(), arm, arm_state_joints(), params);
    if (!choice.found) return;
    const Eigen::Vector3d other = candidates[1 - choice.target.index].position;
    const double gap = least_link_gap(choice, arm, arm_state_joints(), other, params);
    if (choice.note.find("no clear push left") != std::string::npos) {
      // Taken only when no push of either cleared everything: then the note says what it risks.
      if (gap < arm.nudge.link_clearance) {
        EXPECT_NE(choice.note.find("the arm's links would pass within"), std::string::npos) << choice.note;
      }
      return;
    }
    ++strict;
    EXPECT_GE(gap, arm.nudge.link_clearance) << sv::millimetres(first) << " and " << sv::millimetres(second);
    // Without the check the same pair may be pushed with the links through the other object.
    const auto blind = sv::choose_target(candidates, {}, scene.right_camera_in_world(), arm, arm_state_joints(), unchecked);
    ASSERT_TRUE(blind.found);
    if (least_link_gap(blind, arm, arm_state_joints(), candidates[1 - blind.target.index].position, params) < arm.nudge.link_clearance)
      ++mended;
  });
  EXPECT_GT(strict, 20);
  EXPECT_GT(mended, 0);  // the check changes choices: without it some links pass through an object
  EXPECT_GT(beside_clear, 20);
  EXPECT_GT(known_spared, 0) << "a push sweeping the explored object is refused where an unknown one's is taken last";
}

// The thesis' straight-down tool (no lean): its wrist rides beside the pushed object, so some
// pushes clear a cup but not the tallest object expected.
sv::ArmSetup straight_down_arm() {
  sv::ArmSetup arm;
  arm.nudge.tool_tilt = 0;
  return arm;
}
// Such a place: a 0.25 m object there is struck by the wrist, a 0.08 m one is not.
const Eigen::Vector3d kWristNearTallObject(0.26, 0.045, 0);

TEST(Targets, APushTooNearTheTallestObjectIsChosenForTheTallestObjectItClears) {
  const sv::SceneGeometry scene = make_scene();
  const sv::ArmSetup arm = straight_down_arm();
  const std::vector<sv::Candidate> candidates = {{0, kWristNearTallObject, 9}};
  const auto choice = sv::choose_target(candidates, {}, scene.right_camera_in_world(), arm, arm_state_joints(), sv::TargetParams{});
  ASSERT_TRUE(choice.found);
  EXPECT_GE(choice.height_limit, sv::TargetParams{}.shortest_height_limit);
  EXPECT_LT(choice.height_limit, arm.nudge.object_height);
  // The tallest it clears, to within the bisection's step: a centimetre more is refused.
  nudge::robot::NudgeParams taller = arm.nudge;
  taller.object_height = choice.height_limit + 2 * sv::TargetParams{}.height_limit_step;
  EXPECT_FALSE(nudge::robot::plan_nudge(arm.model, arm.safety_config(), arm.point_to_base(kWristNearTallObject),
                                        arm.direction_to_base(choice.direction), taller, arm_state_joints())
                   .ok());
  // Without such pushes it is passed over with the arm's reason.
  sv::TargetParams never;
  never.shortest_height_limit = 0;
  const auto refused = sv::choose_target(candidates, {}, scene.right_camera_in_world(), arm, arm_state_joints(), never);
  EXPECT_FALSE(refused.found);
  ASSERT_EQ(refused.rejected.size(), 1u);
  EXPECT_NE(refused.rejected[0].reason.find("forearm or wrist"), std::string::npos) << refused.rejected[0].reason;
  // With the lean the same place clears the tallest object: no limit.
  const auto leaned = sv::choose_target(candidates, {}, scene.right_camera_in_world(), sv::ArmSetup{}, arm_state_joints(),
                                        sv::TargetParams{});
  ASSERT_TRUE(leaned.found);
  EXPECT_EQ(leaned.height_limit, 0.0);
}

TEST(Targets, APlaceNeitherPushAcrossTheViewReachesIsPushedTurnedOffIt) {
  const sv::SceneGeometry scene = make_scene();
  const sv::ArmSetup arm;
  sv::TargetParams across_only;
  across_only.max_push_turn_deg = 0;
  // Over the workspace ring, the places the arm pushes only turned off across the view.
  int turned = 0;
  for (double radius = 0.16; radius <= 0.34; radius += 0.03)
    for (double bearing = -90; bearing <= 90; bearing += 15) {
      const double b = bearing * M_PI / 180;
      const std::vector<sv::Candidate> candidates = {{0, Eigen::Vector3d(radius * std::cos(b), radius * std::sin(b), 0), 9}};
      const auto thesis = sv::choose_target(candidates, {}, scene.right_camera_in_world(), arm, arm_state_joints(), across_only);
      if (thesis.found) continue;
      const auto choice = sv::choose_target(candidates, {}, scene.right_camera_in_world(), arm, arm_state_joints(), sv::TargetParams{});
      if (!choice.found) {
        EXPECT_NE(choice.rejected.at(0).reason.find("pushes turned up to 40 deg off across the view: none planned"), std::string::npos)
            << choice.rejected[0].reason;
        continue;
      }
      ++turned;
      // Turned by a multiple of the step, no further than the limit, and saying so.
      const Eigen::Vector3d ray = (candidates[0].position - scene.right_camera_in_world()).normalized();
      const double off_deg = std::asin(std::abs(choice.direction.dot(Eigen::Vector3d(ray.x(), ray.y(), 0).normalized()))) * 180 / M_PI;
      EXPECT_NEAR(off_deg, choice.push_turn_deg, 1e-6);
      EXPECT_TRUE(choice.push_turn_deg == 20 || choice.push_turn_deg == 40) << choice.push_turn_deg;
      EXPECT_NE(choice.note.find("deg off across the view"), std::string::npos) << choice.note;
      EXPECT_TRUE(choice.plan.ok());
    }
  EXPECT_GT(turned, 0);
}

// With learning, of the two ways across the view the one that leaves the object where the arm can
// grasp it comes first (TargetParams::rest_travel): over the workspace ring, pushes that left the
// object ungraspable (towards the arm's base, joint 3's limit) turn to the other way where it
// plans, and no place is left worse off.
TEST(Targets, WithLearningThePushThatLeavesTheObjectGraspableComesFirst) {
  const sv::SceneGeometry scene = make_scene();
  const sv::ArmSetup arm;
  sv::TargetParams learning;
  learning.rest_travel = 0.025;
  auto graspable_rest = [&](const sv::TargetChoice& choice) {
    nudge::robot::Command grasp;
    grasp.kind = nudge::robot::CommandKind::Grasp;
    grasp.target_position = choice.target.position + learning.rest_travel * choice.direction;
    grasp.height = learning.rest_grasp_height;
    return nudge::robot::plan_command(arm.planner(), grasp, arm_state_joints()).ok();
  };
  int mended = 0, places = 0;
  for (double radius = 0.16; radius <= 0.34; radius += 0.015)
    for (double bearing = -90; bearing <= 90; bearing += 15) {
      const double b = bearing * M_PI / 180;
      const std::vector<sv::Candidate> candidates = {{0, Eigen::Vector3d(radius * std::cos(b), radius * std::sin(b), 0), 9}};
      const auto before = sv::choose_target(candidates, {}, scene.right_camera_in_world(), arm, arm_state_joints(), sv::TargetParams{});
      const auto choice = sv::choose_target(candidates, {}, scene.right_camera_in_world(), arm, arm_state_joints(), learning);
      ASSERT_EQ(before.found, choice.found) << "the order changes, not which places are pushed";
      if (!choice.found) continue;
      ++places;
      EXPECT_TRUE(choice.plan.ok());
      if (graspable_rest(before)) {
        EXPECT_TRUE(graspable_rest(choice)) << "radius " << radius << " bearing " << bearing;
        EXPECT_NEAR((choice.direction - before.direction).norm(), 0.0, 1e-9) << "already graspable: the same push";
      } else if (graspable_rest(choice)) {
        ++mended;
      }
    }
  EXPECT_GT(places, 20);
  EXPECT_GT(mended, 0) << "some pushes over the ring left the object ungraspable, and the other way does not";
}

TEST(ObjectHeight, TheRayIsReadWhereItPassesOverTheAxis) {
  const sv::SceneGeometry scene = make_scene();
  const Eigen::Vector3d foot(0.28, -0.05, 0);
  for (const cv::Size size : {cv::Size(640, 480), cv::Size(1280, 960)})
    for (double height : {0.0, 0.06, 0.12, 0.2}) {
      const auto pixel = scene.project_right(foot + Eigen::Vector3d(0, 0, height), size);
      ASSERT_TRUE(pixel);
      const auto read = sv::ray_height_over(scene, foot, *pixel, size);
      ASSERT_TRUE(read);
      EXPECT_NEAR(*read, height, 1e-6) << size << " " << height;
    }
  // A point of the rim behind the axis (a top seen from above) reads higher: the error is safe.
  Eigen::Vector3d behind = foot - scene.right_camera_in_world();
  behind.z() = 0;
  const Eigen::Vector3d rim = foot + 0.03 * behind.normalized() + Eigen::Vector3d(0, 0, 0.12);
  const auto read = sv::ray_height_over(scene, foot, *scene.project_right(rim, {1280, 960}), {1280, 960});
  ASSERT_TRUE(read);
  EXPECT_GT(*read, 0.12 + 0.01);
}

TEST(ObjectHeight, TheTopOfTheSymmetricOutlineInTheStillIsTheObjectsHeight) {
  const sv::SceneGeometry scene = make_scene();
  const cv::Size size(1280, 960);
  for (const Eigen::Vector3d& foot : {Eigen::Vector3d(0.28, -0.05, 0), Eigen::Vector3d(0.22, 0.12, 0)}) {
    const cv::Mat still = draw_scene(scene, size, {foot});  // 0.12 m tall
    const auto line = sv::find_line_near(still, *scene.right_axis_line(foot, 0.25, size));
    ASSERT_TRUE(line);
    const auto height = sv::measure_object_height(scene, still, *line, foot);
    ASSERT_TRUE(height);
    EXPECT_NEAR(*height, 0.12, 0.006) << foot.transpose();
  }
  // Nothing symmetric there: no height.
  const Eigen::Vector3d foot(0.28, -0.05, 0);
  const cv::Mat empty = draw_scene(scene, size, {});
  EXPECT_FALSE(sv::measure_object_height(scene, empty, *scene.right_axis_line(foot, 0.25, size), foot));
  sv::HeightParams bad;
  bad.margin_m = -0.01;
  EXPECT_THROW(sv::validate(bad), std::invalid_argument);
}

TEST(ObjectHeight, TheLinesFootTellsHowFarACandidateStandsBeyondTheFrontOfTheObject) {
  const sv::SceneGeometry scene = make_scene();
  const cv::Size size(1280, 960);
  const Eigen::Vector3d foot(0.28, -0.05, 0);
  // A line whose support runs from the foot up 0.12 m: the candidate at the foot stands 0 beyond
  // it; one further along the camera's view stands that much beyond.
  nudge::symmetry::Line line = *scene.right_axis_line(foot, 0.25, size);
  line.seg1 = *scene.project_right(foot, size);
  line.seg2 = *scene.project_right(foot + Eigen::Vector3d(0, 0, 0.12), size);
  Eigen::Vector3d view = foot - scene.right_camera_in_world();
  view.z() = 0;
  view.normalize();
  for (double beyond : {-0.03, 0.0, 0.04, 0.09}) {
    const auto depth = sv::depth_beyond_line_foot(scene, line, foot + beyond * view, size);
    ASSERT_TRUE(depth) << beyond;
    EXPECT_NEAR(*depth, beyond, 1e-6);
  }
  std::swap(line.seg1, line.seg2);  // the lower end is the lower end whichever way round
  EXPECT_NEAR(*sv::depth_beyond_line_foot(scene, line, foot, size), 0.0, 1e-6);
  line.seg2 = line.seg1;  // no support: no foot
  EXPECT_FALSE(sv::depth_beyond_line_foot(scene, line, foot, size));
}

// Where the arm with its leaning tool clears an object only up to about 0.15 m (behind the base:
// the lean cannot take the wrist far enough off the object).
const Eigen::Vector3d kLeanedWristNearTallObject(-0.0561, 0.2641, 0);

TEST_F(SupervisorTest, APushClearingOnlyAShortObjectIsMadeWhenTheStillMeasuresItShorter) {
  const auto choice = sv::choose_target({{0, kLeanedWristNearTallObject, 9}}, {}, scene_.right_camera_in_world(), sv::ArmSetup{},
                                        arm_state_joints(), sv::TargetParams{});
  ASSERT_TRUE(choice.found);
  ASSERT_GT(choice.height_limit, 0.135);  // the drawn object, 0.12 m, and a margin of 5 mm fit under it
  sv::Config config = drawn_config();
  config.height.margin_m = 0.005;
  sv::Supervisor s(config, scene_, sv::ArmSetup{}, mask_of_difference);
  start_with(s, {kLeanedWristNearTallObject});
  s.on_right_still(draw_scene(scene_, {1280, 960}, {kLeanedWristNearTallObject}), now_, now_);
  const auto nudges = outputs_of<sv::NudgeCommand>(s.take_outputs());
  ASSERT_EQ(nudges.size(), 1u) << s.report().reason;
  // The drawn object is 0.12 m tall; the arm is told that plus the margin.
  EXPECT_NEAR(nudges[0].object_height, 0.12 + config.height.margin_m, 0.006);
  // A push that clears any object leaves the arm's default.
  sv::Supervisor leaned = make();
  EXPECT_EQ(nudge_command_for(leaned, Eigen::Vector3d(0.28, -0.05, 0)).object_height, 0.0);
}

TEST_F(SupervisorTest, APushClearingOnlyAShortObjectIsRefusedWhenTheStillMeasuresItTaller) {
  sv::Config config = drawn_config();
  config.height.margin_m = 0.2;  // as if the object were 0.32 m tall
  sv::Supervisor s(config, scene_, straight_down_arm(), mask_of_difference);
  start_with(s, {kWristNearTallObject});
  s.on_right_still(draw_scene(scene_, {1280, 960}, {kWristNearTallObject}), now_, now_);
  auto out = s.take_outputs();
  EXPECT_TRUE(outputs_of<sv::NudgeCommand>(out).empty());
  auto ended = outputs_of<sv::AttemptEnded>(out);
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(ended[0].attempt->outcome, sv::Outcome::Refused);
  EXPECT_NE(ended[0].attempt->reason.find("the push clears only an object"), std::string::npos) << ended[0].attempt->reason;
  ASSERT_TRUE(ended[0].attempt->measured_height);
  EXPECT_NEAR(*ended[0].attempt->measured_height, 0.12, 0.006);
  // Not measured at all (nothing symmetric where it stands): refused too, with its reason.
  sv::Supervisor blind(drawn_config(), scene_, straight_down_arm(), mask_of_difference);
  start_with(blind, {kWristNearTallObject});
  blind.on_right_still(draw_scene(scene_, {1280, 960}, {}), now_, now_);
  ended = outputs_of<sv::AttemptEnded>(blind.take_outputs());
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(ended[0].attempt->outcome, sv::Outcome::Refused);
  EXPECT_NE(ended[0].attempt->reason.find("height was not measured"), std::string::npos) << ended[0].attempt->reason;
}

TEST_F(SupervisorTest, SegmentsTheObjectThenFindsNothingLeftToNudge) {
  sv::Config with_trackers = drawn_config();
  with_trackers.track = true;
  sv::Supervisor s = make(with_trackers);
  const Eigen::Vector3d object(0.28, -0.05, 0);
  auto out = start_with(s, {object});
  ASSERT_EQ(outputs_of<sv::SnapshotRequest>(out).size(), 1u);
  EXPECT_EQ(s.state(), sv::State::SnapshotBefore);
  now_ += kSecond / 5;
  s.on_right_still(draw_scene(scene_, {1280, 960}, {object}), now_, now_);
  out = s.take_outputs();
  const auto nudges = outputs_of<sv::NudgeCommand>(out);
  ASSERT_EQ(nudges.size(), 1u);
  EXPECT_EQ(nudges[0].seq, 100);
  EXPECT_NEAR((nudges[0].target - object).norm(), 0.0, 1e-12);
  const Eigen::Vector3d rest = object + 0.03 * nudges[0].direction;
  play_nudge(s, nudges[0].seq, object, rest);
  EXPECT_EQ(s.state(), sv::State::Track);
  EXPECT_EQ(s.report().failed_attempts, 0) << "the attempt under way has not failed";
  EXPECT_EQ(s.report().segmented, 0);
  settle_with_axes(s, {rest + Eigen::Vector3d(0.002, -0.001, 0)});
  // The arm parks (COMMAND_HOME) before the after still, so that it is where it was for the first.
  ASSERT_EQ(s.state(), sv::State::Home) << s.report().reason;
  const auto homes = outputs_of<sv::HomeCommand>(s.take_outputs());
  ASSERT_EQ(homes.size(), 1u);
  EXPECT_EQ(s.awaited_arm_seq(), homes[0].seq);
  s.on_arm_state(arm(sv::ArmStatus::Motion::Moving, homes[0].seq), now_ += kSecond);
  EXPECT_EQ(s.state(), sv::State::Home);
  s.on_arm_state(arm(sv::ArmStatus::Motion::Done, homes[0].seq), now_ += kSecond);
  ASSERT_EQ(s.state(), sv::State::SnapshotAfter) << s.report().reason;
  now_ += kSecond / 5;
  const int64_t after_taken = now_ - kSecond / 10;  // taken after the request, heard later
  s.on_right_still(draw_scene(scene_, {1280, 960}, {rest}), after_taken, now_);
  out = s.take_outputs();
  const auto ended = outputs_of<sv::AttemptEnded>(out);
  ASSERT_EQ(ended.size(), 1u);
  const sv::Attempt& a = *ended[0].attempt;
  EXPECT_EQ(a.outcome, sv::Outcome::Segmented) << a.reason;
  EXPECT_EQ(a.after_utime, after_taken) << "segmentation_t.utime is the after still's time";
  EXPECT_GE(a.motion_frames, 2);
  ASSERT_TRUE(a.rest);
  EXPECT_LT((*a.rest - rest).norm(), 0.005);
  EXPECT_GT(cv::countNonZero(a.segmentation.mask), 1000);
  // Measured where it stands, for later pushes' links: the box is 12 cm tall; the measurement errs
  // high (its top face seen from above) and carries the 2 cm margin.
  EXPECT_GT(a.standing_height, 0.115 + sv::HeightParams{}.margin_m);
  EXPECT_LT(a.standing_height, 0.20);
  // The readings it came from are kept: the box's edges in the after still and the mask's top;
  // the height the arm is told is the higher plus the margin.
  ASSERT_TRUE(a.height_from_edges && a.height_from_mask);
  for (const double reading : {*a.height_from_edges, *a.height_from_mask}) {
    EXPECT_GT(reading, 0.115);
    EXPECT_LT(reading, 0.18);
  }
  EXPECT_NEAR(a.standing_height, std::max(*a.height_from_edges, *a.height_from_mask) + sv::HeightParams{}.margin_m, 1e-9);
  // The next survey leaves the segmented object's lines out, where it now stands.
  const auto surveys = outputs_of<sv::CandidatesRequest>(out);
  ASSERT_EQ(surveys.size(), 1u);
  ASSERT_EQ(surveys[0].explored.size(), 1u);
  EXPECT_NEAR((surveys[0].explored[0] - *a.rest).norm(), 0.0, 1e-12);
  ASSERT_TRUE(a.before_line && a.after_line);
  // The lines found in the stills are the object's: where the calibration predicts them, apart
  // by the slide (3 cm at ~0.75 m is ~45 px at 1280x960).
  const auto predicted = scene_.right_axis_line(rest, 0.2, {1280, 960});
  EXPECT_NEAR(a.after_line->r, predicted->r, 8.0);  // 4 px at 640x480
  // Both trackers followed it: their last lines are where it came to rest.
  ASSERT_TRUE(a.tracked[0] && a.tracked[1]);
  EXPECT_NEAR(a.tracked[1]->r, scene_.right_axis_line(rest, 0.2, {640, 480})->r, 4.0);
  EXPECT_NEAR(a.tracked[0]->r, scene_.left_axis_line(rest, 0.2, {640, 480})->r, 4.0);
  EXPECT_GT(std::abs(a.after_line->r - a.before_line->r), 25.0);
  EXPECT_TRUE(outputs_of<sv::HomeCommand>(out).empty()) << "parked already";
  EXPECT_EQ(s.state(), sv::State::FindCandidates);
  // The same place again (and the object's new place): nothing new to nudge.
  out = answer_survey(s, {object, rest});
  EXPECT_EQ(s.state(), sv::State::Done);
  EXPECT_EQ(s.summary().segmented, 1);
  EXPECT_EQ(s.summary().attempts, 1);
  EXPECT_EQ(s.report().segmented, 1);
  EXPECT_EQ(s.report().failed_attempts, 0);
  ASSERT_EQ(outputs_of<sv::Finished>(out).size(), 1u);
  EXPECT_NE(s.summary().end_reason.find("no nudgeable candidate left"), std::string::npos) << s.summary().end_reason;
}

TEST_F(SupervisorTest, NoCandidateAtAllEndsTheRunWithItsReason) {
  sv::Supervisor s = make();
  start_with(s, {});
  EXPECT_EQ(s.state(), sv::State::Done);
  EXPECT_EQ(s.summary().end_reason, "no candidate found on the table");
}

// A survey that leaves nothing to nudge is asked once more, with survey lines further from
// upright, before the run ends (a lone bottle whose label leans its line past the service's 2 deg);
// what the second look finds is nudged.
TEST_F(SupervisorTest, AnEmptySurveyIsAskedOnceMoreWithWiderLinesBeforeTheRunEnds) {
  sv::Config config = drawn_config();
  config.wide_survey_tilt_deg = 5;
  for (bool found_later : {false, true}) {
    sv::Supervisor s = make(config);
    s.start(now_, 100);
    s.on_services({}, now_);
    const auto first = outputs_of<sv::CandidatesRequest>(s.take_outputs());
    ASSERT_EQ(first.size(), 1u);
    EXPECT_EQ(first[0].max_line_tilt_deg, 0) << "the first survey is the service's own";
    const auto second = outputs_of<sv::CandidatesRequest>(answer_survey(s, {}));
    ASSERT_EQ(s.state(), sv::State::FindCandidates) << s.report().reason;
    ASSERT_EQ(second.size(), 1u);
    EXPECT_EQ(second[0].max_line_tilt_deg, 5);
    EXPECT_NE(s.report().reason.find("no candidate found on the table: a second look"), std::string::npos)
        << s.report().reason;
    EXPECT_NE(s.report().reason.find("up to 5 deg from upright"), std::string::npos) << s.report().reason;
    if (found_later) {
      // Both cameras saw the object's lines leaning 4 deg about its middle: too far for a
      // survey's agreement (3 deg), near enough for the second look's.
      const Eigen::Vector3d object(0.28, -0.05, 0);
      for (int i = 0; i < 10; ++i)
        for (bool left : {true, false}) {
          const auto axis = left ? scene_.left_axis_line(object, 0.25, {640, 480}) : scene_.right_axis_line(object, 0.25, {640, 480});
          ASSERT_TRUE(axis);
          s.on_lines(left, {leaning(*axis, 4.0, {640, 480})}, now_ + kSecond / 10, now_ + kSecond / 5);
        }
      answer_survey(s, {object});
      EXPECT_NE(s.state(), sv::State::Done) << s.summary().end_reason;
      EXPECT_EQ(s.summary().attempts, 1);
    } else {
      answer_survey(s, {});
      EXPECT_EQ(s.state(), sv::State::Done);
      EXPECT_EQ(s.summary().end_reason, "no candidate found on the table");
      EXPECT_EQ(s.summary().surveys, 2) << "one second look, not more";
    }
  }
}

TEST_F(SupervisorTest, EveryCandidateOutOfReachIsReportedNotNudged) {
  sv::Supervisor s = make();
  const auto out = start_with(s, {Eigen::Vector3d(0.7, 0.0, 0), Eigen::Vector3d(0.0, 0.5, 0)});
  EXPECT_TRUE(outputs_of<sv::NudgeCommand>(out).empty());
  EXPECT_TRUE(outputs_of<sv::SnapshotRequest>(out).empty());
  EXPECT_EQ(s.state(), sv::State::Done);
  EXPECT_NE(s.summary().end_reason.find("out of reach"), std::string::npos) << s.summary().end_reason;
  EXPECT_EQ(s.report().rejected, 2);
}

TEST_F(SupervisorTest, ARefusedNudgeGoesOnToTheNextCandidate) {
  sv::Supervisor s = make();
  const Eigen::Vector3d first(0.28, -0.05, 0), second(0.22, 0.20, 0);
  start_with(s, {first, second});
  s.on_right_still(draw_scene(scene_, {1280, 960}, {first, second}), now_, now_);
  const auto nudge = outputs_of<sv::NudgeCommand>(s.take_outputs()).at(0);
  EXPECT_NEAR((nudge.target - first).norm(), 0.0, 1e-12);  // nearer the camera
  s.on_arm_state(arm(sv::ArmStatus::Motion::Refused, nudge.seq - 1, "an older command"), now_);  // not ours
  EXPECT_EQ(s.state(), sv::State::Nudge);
  s.on_arm_state(arm(sv::ArmStatus::Motion::Refused, nudge.seq, "nudge: elbow below the table"), now_);
  auto out = s.take_outputs();
  const auto ended = outputs_of<sv::AttemptEnded>(out);
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(ended[0].attempt->outcome, sv::Outcome::Refused);
  EXPECT_NE(ended[0].attempt->reason.find("elbow below the table"), std::string::npos);
  out = answer_survey(s, {first, second});
  const auto next = outputs_of<sv::SnapshotRequest>(out);
  ASSERT_EQ(next.size(), 1u);
  EXPECT_NEAR((s.report().target - second).norm(), 0.0, 1e-12);
}

TEST_F(SupervisorTest, APhantomCandidateShowsNoMotionAndIsRecordedAsSuch) {
  sv::Supervisor s = make();
  const Eigen::Vector3d phantom(0.28, -0.05, 0);
  start_with(s, {phantom});
  s.on_right_still(draw_scene(scene_, {1280, 960}, {}), now_, now_);
  const auto nudge = outputs_of<sv::NudgeCommand>(s.take_outputs()).at(0);
  // Nothing stands there: the frames do not change (the arm stays on its own side of the line).
  s.on_arm_state(arm(sv::ArmStatus::Motion::Moving, nudge.seq), now_);
  for (int i = 0; i < 10; ++i) {
    now_ += kSecond / 10;
    show(s, {});
  }
  s.on_arm_state(arm(sv::ArmStatus::Motion::Done, nudge.seq), now_);
  settle_with_axes(s, {});
  const auto ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(ended[0].attempt->outcome, sv::Outcome::NoMotion);
  EXPECT_NE(ended[0].attempt->reason.find("phantom"), std::string::npos);
  EXPECT_EQ(s.state(), sv::State::Home);  // the arm parks before the next survey
  park(s);
  EXPECT_EQ(s.state(), sv::State::FindCandidates);
}

// A phantom is where one object's line in one camera meets another's in the other camera: its
// neighbours, and what stands on its lines in a camera, are those objects. A push that moved
// nothing there leaves them to be nudged (development run m03: the yellow cup, 87 mm behind a
// phantom on its right-camera line, and a phantom 45 mm beside it were skipped as "already
// explored", and the run ended with no object segmented).
TEST_F(SupervisorTest, APushThatMovedNothingLeavesThePhantomsNeighboursToBeNudged) {
  const Eigen::Vector3d phantom(0.28, -0.05, 0);
  for (const bool ray_mate : {false, true}) {
    SCOPED_TRACE(ray_mate ? "on the phantom's line in the right camera" : "beside the phantom");
    sv::Supervisor s = make();
    const sv::NudgeCommand nudge = nudge_command_for(s, phantom);
    // Something moved in the push's frames, but the symmetric axes still stand where they stood.
    play_nudge(s, nudge.seq, phantom, phantom + 0.03 * nudge.direction);
    settle_with_axes(s, {phantom});
    const auto ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
    ASSERT_EQ(ended.size(), 1u);
    ASSERT_EQ(ended[0].attempt->outcome, sv::Outcome::NoMotion) << ended[0].attempt->reason;
    const Eigen::Vector3d object = ray_mate ? Eigen::Vector3d(phantom + 0.08 * along_ray(phantom))
                                            : Eigen::Vector3d(phantom + Eigen::Vector3d(0.03, 0.035, 0));
    const auto out = answer_survey(s, {phantom, object});
    ASSERT_EQ(s.state(), sv::State::SnapshotBefore) << s.summary().end_reason;
    EXPECT_NEAR((s.report().target - object).norm(), 0.0, 1e-12);
  }
}

// An upright object's triangulated axis leans by its measurement's noise: up to 12.6 deg for
// upright objects in the development runs (docs/supervisor.md, "The tip limit"). 14 deg is still
// standing; the next still is taken.
TEST_F(SupervisorTest, AnAxisLeaningByMeasurementNoiseIsNotATip) {
  sv::Supervisor s = make();
  const Eigen::Vector3d object(0.28, -0.05, 0);
  const sv::NudgeCommand nudge = nudge_command_for(s, object);
  play_nudge(s, nudge.seq, object, object + 0.03 * nudge.direction);
  settle_with_axes(s, {object + 0.03 * nudge.direction}, /*tilt=*/14 * M_PI / 180);
  park(s);
  EXPECT_EQ(s.state(), sv::State::SnapshotAfter) << s.report().reason;
}

TEST_F(SupervisorTest, ATippedObjectIsReportedNotSegmented) {
  sv::Supervisor s = make();  // without trackers: the settled AXES decide
  const Eigen::Vector3d object(0.28, -0.05, 0);
  const sv::NudgeCommand nudge = nudge_command_for(s, object);
  play_nudge(s, nudge.seq, object, object + 0.03 * nudge.direction);
  settle_with_axes(s, {object + 0.03 * nudge.direction}, /*tilt=*/0.4);  // 23 deg from upright
  auto ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(ended[0].attempt->outcome, sv::Outcome::Tipped);
  ASSERT_TRUE(ended[0].attempt->rest_tilt_deg) << "the measured lean is kept (attempt.json)";
  EXPECT_NEAR(*ended[0].attempt->rest_tilt_deg, 0.4 * 180 / M_PI, 0.1);
  EXPECT_TRUE(ended[0].attempt->after.empty());  // no still taken, nothing segmented
  EXPECT_EQ(s.report().failed_attempts, 1) << "an ended attempt that segmented nothing";
  // Lying down it has no upright axis at all, and no upright line along the push in the after
  // still: also reported.
  answer_survey(s, {Eigen::Vector3d(0.30, 0.10, 0)});
  s.on_right_still(draw_scene(scene_, {1280, 960}, {Eigen::Vector3d(0.30, 0.10, 0)}), now_, now_);
  const auto second = outputs_of<sv::NudgeCommand>(s.take_outputs()).at(0);
  play_nudge(s, second.seq, second.target, second.target + 0.03 * second.direction);
  settle_with_axes(s, {});
  const auto lying = park_and_show_after_still_of(s, {});
  ASSERT_TRUE(lying);
  EXPECT_EQ(lying->outcome, sv::Outcome::Tipped);
  EXPECT_NE(lying->reason.find("no new upright line along the push"), std::string::npos) << lying->reason;
  EXPECT_EQ(s.report().failed_attempts, 2);
}

// A push that topples the object may leave another object's settled axes near the push line,
// leaning within the upright limit (development m03, hm2: 10.9 and 11.2 deg, the bottles lying on
// the table), and the motion makes a mask all the same (IoU 0.24, 0.29). Such a lean is doubtful:
// the mask must show an upright object's base, or the attempt is tipped, not segmented.
TEST_F(SupervisorTest, ADoubtfulLeanWhoseMaskShowsNoBaseIsTipped) {
  // A solid upright mask 81 px wide about the after line over the moved object's rows; without a
  // base its lower 40 % is only 17 px wide (a fallen bottle's neck across the line).
  auto segment_with_base = [](bool base) {
    return [base](const cv::Mat& before, const cv::Mat& after, const nudge::symmetry::Line& l0,
                  const nudge::symmetry::Line& l1) {
      sv::Segmentation s = mask_of_difference(before, after, l0, l1);
      const cv::Rect box = cv::boundingRect(s.mask);
      const int base_top = box.y + box.height * 6 / 10;
      cv::Mat body = cv::Mat::zeros(s.mask.size(), CV_8U), neck = body.clone();
      body.rowRange(box.y, base ? box.br().y : base_top).setTo(255);
      nudge::segmentation::keep_near_line(body, l1, 40);
      neck.rowRange(base_top, box.br().y).setTo(255);
      nudge::segmentation::keep_near_line(neck, l1, 8);
      s.mask = body | neck;
      return s;
    };
  };
  auto attempt = [&](const sv::Config& config, bool base, double tilt_deg) {
    sv::Supervisor s(config, scene_, sv::ArmSetup{}, segment_with_base(base));
    const Eigen::Vector3d object(0.28, -0.05, 0);
    const sv::NudgeCommand nudge = nudge_command_for(s, object);
    const Eigen::Vector3d rest = object + 0.03 * nudge.direction;
    play_nudge(s, nudge.seq, object, rest);
    settle_with_axes(s, {rest}, tilt_deg * M_PI / 180);
    return park_and_show_after_still_of(s, {rest});
  };
  struct Case {
    double tilt_deg;
    bool base;
    sv::Outcome outcome;
  };
  for (const Case& c : {Case{11, false, sv::Outcome::Tipped}, Case{11, true, sv::Outcome::Segmented},
                        Case{3, false, sv::Outcome::Segmented}}) {
    SCOPED_TRACE(std::to_string(c.tilt_deg) + (c.base ? " deg, with a base" : " deg, no base"));
    const auto a = attempt(drawn_config(), c.base, c.tilt_deg);
    ASSERT_TRUE(a);
    EXPECT_EQ(a->outcome, c.outcome) << a->reason;
    EXPECT_EQ(a->rest_from_mask.has_value(), c.base) << "the base gives the mask's foot";
    if (c.outcome == sv::Outcome::Tipped) {
      EXPECT_NE(a->reason.find("shows no upright object's base"), std::string::npos) << a->reason;
    }
  }
  // Off, the doubtful lean is segmented as before.
  sv::Config off = drawn_config();
  off.doubtful_tilt_deg = 0;
  const auto a = attempt(off, false, 11);
  ASSERT_TRUE(a);
  EXPECT_EQ(a->outcome, sv::Outcome::Segmented) << a->reason;
}

// A known object standing in front may hide the base of the next target's mask. That vouches for
// a doubtful lean only when the survey counted the target as an object: a candidate seen in one
// pair of 25 (second development set, hm2) whose axes leaned 11.9 deg behind the clear bottle
// segmented there was two labels the push stirred (IoU 0.136).
TEST_F(SupervisorTest, AHiddenBaseVouchesForADoubtfulLeanOnlyOfATargetTheSurveyCountedAsAnObject) {
  Eigen::Vector3d towards = scene_.right_camera_in_world() - Eigen::Vector3d(0.22, -0.10, 0);
  towards.z() = 0;
  towards.normalize();
  const Eigen::Vector3d across(0, 1, 0);  // draw_scene's boxes face across world y
  const Shape front_shape{0.12, 0.07}, behind_shape{0.22, 0.035};  // a wide box in front
  // The second object's mask: its upright silhouette where it rests, less the box in front.
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> behind_and_front;
  auto segment = [&](const cv::Mat& before, const cv::Mat& after, const nudge::symmetry::Line& l0,
                     const nudge::symmetry::Line& l1) {
    if (!behind_and_front) return mask_of_difference(before, after, l0, l1);
    const auto& [rest, front] = *behind_and_front;
    sv::Segmentation s;
    s.mask = cylinder_mask(scene_, after.size(), rest, behind_shape.half_width, behind_shape.height) &
             ~cylinder_mask(scene_, after.size(), front, front_shape.half_width, front_shape.height);
    return s;
  };
  auto attempt = [&](int frames_seen_of_10) -> std::shared_ptr<const sv::Attempt> {
    behind_and_front.reset();
    sv::Supervisor s(drawn_config(), scene_, sv::ArmSetup{}, segment);
    // First the object in front: nudged, segmented, known where it rests.
    const Eigen::Vector3d found = Eigen::Vector3d(0.22, -0.10, 0) + 0.10 * towards;
    const sv::NudgeCommand first_nudge = nudge_command_for(s, found, front_shape);
    const Eigen::Vector3d front = found + 0.03 * first_nudge.direction;
    play_nudge(s, first_nudge.seq, found, front);
    settle_with_axes(s, {front});
    const auto first = park_and_show_after_still_of(s, {front}, {front_shape});
    if (!first || first->outcome != sv::Outcome::Segmented) {
      ADD_FAILURE() << "the object in front was not segmented";
      return nullptr;
    }
    // Then the one behind it, seen in `frames_seen_of_10` of the survey's pairs.
    const Eigen::Vector3d behind = front - 0.10 * towards + 0.04 * across;
    park(s);
    s.take_outputs();
    if (s.state() != sv::State::FindCandidates) {
      ADD_FAILURE() << "no second survey: " << s.report().reason;
      return nullptr;
    }
    hear_survey_lines(s, behind, frames_seen_of_10);
    hear_survey_lines(s, front, 10 - frames_seen_of_10);
    now_ += 3 * kSecond;
    s.on_candidates({{0, behind, 20}}, now_, now_);
    s.take_outputs();
    s.on_right_still(draw_scene(scene_, {1280, 960}, {behind, front}, false, {behind_shape, front_shape}), now_, now_);
    const auto nudges = outputs_of<sv::NudgeCommand>(s.take_outputs());
    if (nudges.size() != 1u) {
      std::string why;
      for (const auto& [reason, count] : s.summary().rejections) why += "; " + reason;
      ADD_FAILURE() << "the one behind was not nudged: " << s.report().reason << why;
      return nullptr;
    }
    const Eigen::Vector3d rest = behind + 0.02 * nudges[0].direction;
    play_nudge(s, nudges[0].seq, behind, rest, {front});
    settle_with_axes(s, {rest}, 11 * M_PI / 180);
    behind_and_front = std::make_pair(rest, front);
    return park_and_show_after_still_of(s, {rest, front}, {behind_shape, front_shape});
  };
  const auto counted = attempt(10);
  ASSERT_TRUE(counted);
  EXPECT_TRUE(counted->mask_front_hidden_behind) << "the object in front hides the mask's base";
  EXPECT_EQ(counted->outcome, sv::Outcome::Segmented) << counted->reason;
  const auto doubted = attempt(1);
  ASSERT_TRUE(doubted);
  EXPECT_TRUE(doubted->mask_front_hidden_behind);
  EXPECT_NEAR(doubted->target.stereo_agreement, 0.1, 1e-9);
  EXPECT_EQ(doubted->outcome, sv::Outcome::Tipped) << doubted->reason;
  EXPECT_NE(doubted->reason.find("hidden by the known object"), std::string::npos) << doubted->reason;
}

// A clear or frosted bottle before a busy background is seldom paired in both cameras: after the
// push no settled axis placed it, though it slid upright (held-out h11: 1.7 cm, development s09:
// 2.1 cm) and was called tipped. The right after still shows it: a new upright line along the push.
TEST_F(SupervisorTest, AnObjectNoSettledAxisPlacedIsFoundAsANewLineAlongThePush) {
  const Eigen::Vector3d object(0.28, -0.05, 0);
  for (const bool from_still : {true, false}) {
    SCOPED_TRACE(from_still ? "rest from the still" : "no rest from the still");
    sv::Config config = drawn_config();
    config.rest_from_still = from_still;
    sv::Supervisor s = make(config);
    const sv::NudgeCommand nudge = nudge_command_for(s, object);
    const Eigen::Vector3d rest = object + 0.02 * nudge.direction;
    play_nudge(s, nudge.seq, object, rest);
    settle_with_axes(s, {});  // the settled frames' AXES came, none of them the object's
    if (!from_still) {
      const auto ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
      ASSERT_EQ(ended.size(), 1u);
      EXPECT_EQ(ended[0].attempt->outcome, sv::Outcome::Tipped);
      continue;
    }
    const auto attempt = park_and_show_after_still(s, rest);
    ASSERT_TRUE(attempt && attempt->rest && attempt->after_line);
    EXPECT_EQ(attempt->outcome, sv::Outcome::Segmented) << attempt->reason;
    EXPECT_TRUE(attempt->rest_from_still);
    EXPECT_LT((*attempt->rest - rest).norm(), 0.005) << "where an upright axis on the push line meets its line";
    const auto rest_line = scene_.right_axis_line(rest, 0.25, {1280, 960});
    ASSERT_TRUE(rest_line);
    EXPECT_LT(std::abs(nudge::symmetry::line_difference(*attempt->after_line, *rest_line).r), 10);
  }
}

// What stood along the push before it is no new line: a neighbour there, when the pushed object
// tipped over, is not taken for it.
TEST_F(SupervisorTest, ANeighbourStandingAlongThePushIsNotTakenForAnObjectNoSettledAxisPlaced) {
  const Eigen::Vector3d object(0.28, -0.05, 0);
  sv::Config config = drawn_config();
  config.push_travel_m = 0.09;  // where the neighbour stands, clear of the object
  sv::Supervisor s = make(config);
  const auto [nudge, neighbour] = nudge_command_with_neighbour_along(s, config, object, config.push_travel_m);
  play_nudge(s, nudge.seq, object, object + 0.02 * nudge.direction, {neighbour});
  last_objects_ = {neighbour};  // the object fell over: no upright object where it went
  settle_with_axes(s, {});
  const auto attempt = park_and_show_after_still_of(s, {neighbour});
  ASSERT_TRUE(attempt);
  EXPECT_EQ(attempt->outcome, sv::Outcome::Tipped) << attempt->reason;
  EXPECT_NE(attempt->reason.find("no new upright line along the push"), std::string::npos) << attempt->reason;
}

// A pipeline that lags (docs/reliability.md, "Soak": AXES about a second behind under load)
// delivers, after the settling pause, axes of frames taken while the object still rocked: the
// frames' own time decides, so those are not taken for a tipped object.
TEST_F(SupervisorTest, AxesOfFramesTakenWhileTheObjectSettledAreIgnoredHoweverLateTheyArrive) {
  sv::Supervisor s = make();  // without trackers: the settled AXES decide
  const Eigen::Vector3d rest = push_until_settling(s);
  ASSERT_EQ(s.state(), sv::State::Track);
  const int64_t arm_done = now_;
  const int64_t lag = 7 * kSecond / 10;
  const sv::Config config = drawn_config();
  while (s.state() == sv::State::Track && now_ < arm_done + 3 * kSecond) {
    now_ += kSecond / 10;
    const int64_t taken = now_ - lag;
    // Rocking (23 deg) in the frames of the first axes_from_s, upright after.
    const double tilt = taken < arm_done + static_cast<int64_t>(config.axes_from_s * kSecond) ? 0.4 : 0.02;
    s.on_axes({{rest, tilt}}, taken, now_);
    s.on_time(now_);
  }
  EXPECT_TRUE(outputs_of<sv::AttemptEnded>(s.take_outputs()).empty()) << s.report().reason;
  EXPECT_EQ(s.state(), sv::State::Home) << sv::to_string(s.state()) << ": " << s.report().reason;
}

// On a loaded machine the pipeline lagged 2-4 s (the held-out run): when the settling time is
// over, no axes of the settled frames have arrived yet. The loop waits for them (at most
// max_axes_lag_s), and the nudge's camera frames that arrive after the arm's DONE still count.
TEST_F(SupervisorTest, ALaggingPipelineIsWaitedForNotTakenForATippedObjectOrAPhantom) {
  sv::Supervisor s = make();
  const Eigen::Vector3d object(0.28, -0.05, 0);
  const sv::NudgeCommand nudge = nudge_command_for(s, object);
  const Eigen::Vector3d rest = object + 0.03 * nudge.direction;
  // The arm moves and is done before any of the push's frames have arrived.
  const int64_t pushed_from = now_;
  s.on_arm_state(arm(sv::ArmStatus::Motion::Moving, nudge.seq), now_);
  now_ += 2 * kSecond;
  s.on_arm_state(arm(sv::ArmStatus::Motion::Done, nudge.seq), now_);
  ASSERT_EQ(s.state(), sv::State::Track);
  const int64_t arm_done = now_;
  for (int i = -3; i <= 15; ++i) {  // the push's frames, late
    const Eigen::Vector3d at = object + (rest - object) * (std::clamp(i, 0, 15) / 15.0);
    s.on_right_frame(draw_scene(scene_, {640, 480}, {at}), pushed_from + (i + 4) * kSecond / 10);
  }
  const int64_t lag = 3 * kSecond;
  while (s.state() == sv::State::Track && now_ < arm_done + 10 * kSecond) {
    now_ += kSecond / 10;
    if (now_ - lag > arm_done) s.on_axes({{rest, 0.02}}, now_ - lag, now_);
    s.on_time(now_);
  }
  EXPECT_TRUE(outputs_of<sv::AttemptEnded>(s.take_outputs()).empty()) << s.report().reason;
  EXPECT_EQ(s.state(), sv::State::Home) << sv::to_string(s.state()) << ": " << s.report().reason;
  EXPECT_GE(now_, arm_done + lag + static_cast<int64_t>(sv::Config{}.settle_s * kSecond)) << "waited for the axes";
}

// An object that rocks after the push, or one the detection finds only in some frames, may show no
// upright axis in the settling second: the settling goes on, up to max_settle_s, and its axes
// found then place it. Without them by then it is tipped or lost.
TEST_F(SupervisorTest, AnAxisHiddenPastTheSettlingTimeIsWaitedForUpToTheLongestSettling) {
  const sv::Config config = drawn_config();
  for (const double hidden_s : {2.5, config.max_settle_s + 0.5}) {
    SCOPED_TRACE("axes hidden for " + std::to_string(hidden_s) + " s");
    sv::Supervisor s = make();
    const Eigen::Vector3d rest = push_until_settling(s);
    ASSERT_EQ(s.state(), sv::State::Track);
    const int64_t arm_done = now_;
    while (s.state() == sv::State::Track && now_ < arm_done + 20 * kSecond) {
      now_ += kSecond / 10;
      const bool seen = now_ > arm_done + static_cast<int64_t>(hidden_s * kSecond);
      s.on_axes(seen ? std::vector<sv::Axis>{{rest, 0.02}} : std::vector<sv::Axis>{}, now_, now_);
      s.on_time(now_);
    }
    const auto ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
    if (hidden_s < config.max_settle_s) {
      EXPECT_TRUE(ended.empty()) << s.report().reason;
      EXPECT_EQ(s.state(), sv::State::Home) << sv::to_string(s.state()) << ": " << s.report().reason;
      EXPECT_GE(now_, arm_done + static_cast<int64_t>((hidden_s + 0.2) * kSecond)) << "settled on until the axes came";
    } else {
      // Placed neither by the axes nor (the after still shows nothing upright) by the still.
      EXPECT_NEAR(static_cast<double>(now_ - arm_done) / kSecond, config.max_settle_s, 0.15);
      const auto attempt = park_and_show_after_still_of(s, {});
      ASSERT_TRUE(attempt);
      EXPECT_EQ(attempt->outcome, sv::Outcome::Tipped);
      EXPECT_NE(attempt->reason.find("after 4 s of settling"), std::string::npos) << attempt->reason;
    }
  }
}

// A pipeline that never catches up is not waited for forever: tipped or lost after the limit.
TEST_F(SupervisorTest, AxesThatNeverComeEndTheAttemptAfterTheLagLimit) {
  sv::Supervisor s = make();
  const Eigen::Vector3d object(0.28, -0.05, 0);
  const sv::NudgeCommand nudge = nudge_command_for(s, object);
  play_nudge(s, nudge.seq, object, object + 0.03 * nudge.direction);
  const int64_t arm_done = now_;
  const sv::Config config = drawn_config();
  while (s.state() == sv::State::Track && now_ < arm_done + 30 * kSecond) s.on_time(now_ += kSecond / 10);
  const auto ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(ended[0].attempt->outcome, sv::Outcome::Tipped);
  EXPECT_NEAR(static_cast<double>(now_ - arm_done) / kSecond, config.max_settle_s + config.max_axes_lag_s, 0.15);
}

// Lines of frames taken before a survey began (the arm still in view, delivered late) do not
// count towards which candidates both cameras see.
TEST_F(SupervisorTest, SurveyLinesOfFramesFromBeforeTheSurveyAreIgnored) {
  sv::Supervisor s = make();
  const Eigen::Vector3d object(0.28, -0.05, 0);
  s.start(now_, 100);
  s.on_services({}, now_);
  ASSERT_EQ(s.state(), sv::State::FindCandidates);
  // Before the survey: frames that see nothing there. After: frames that see the object.
  for (int i = 0; i < 10; ++i) {
    s.on_lines(true, {}, now_ - kSecond, now_ + i);
    s.on_lines(false, {}, now_ - kSecond, now_ + i);
  }
  hear_survey_lines(s, object, 5);
  now_ += kSecond;
  s.take_outputs();
  s.on_candidates({{0, object, 20}}, now_, now_);
  std::string chosen;
  for (const sv::StateReport& r : outputs_of<sv::StateReport>(s.take_outputs()))
    if (r.state == sv::State::Choose) chosen = r.reason;
  EXPECT_NE(chosen.find("(seen 100%)"), std::string::npos) << chosen;
}

// A candidate's stereo agreement counts each image's lines up to the fifth that is not an explored
// object's (Config::agreement_lines): the symmetry service may publish more, for the surveys after
// an object is explored, whose lines are then left out (the triangulation service's rule).
TEST_F(SupervisorTest, TheStereoAgreementCountsTheLinesASurveyCouldPair) {
  const Eigen::Vector3d first(0.28, -0.05, 0), object(0.24, 0.08, 0);
  const std::vector<Eigen::Vector3d> others = {{0.36, 0.22, 0}, {0.15, -0.17, 0}, {0.40, -0.20, 0}, {0.12, 0.20, 0}};
  // Frames whose lines are the axes of `places`, strongest first.
  auto hear = [&](sv::Supervisor& s, const std::vector<Eigen::Vector3d>& places) {
    for (int frame = 0; frame < 10; ++frame)
      for (const bool left : {true, false}) {
        std::vector<nudge::symmetry::Line> lines;
        for (const Eigen::Vector3d& p : places) {
          const auto line = left ? scene_.left_axis_line(p, 0.25, {640, 480}) : scene_.right_axis_line(p, 0.25, {640, 480});
          ASSERT_TRUE(line);
          lines.push_back(*line);
        }
        s.on_lines(left, lines, now_ + kSecond / 10, now_ + kSecond / 5);
      }
  };
  for (const Eigen::Vector3d& other : others)
    for (const bool left : {true, false}) {
      const auto a = left ? scene_.left_axis_line(other, 0.25, {640, 480}) : scene_.right_axis_line(other, 0.25, {640, 480});
      const auto b = left ? scene_.left_axis_line(object, 0.25, {640, 480}) : scene_.right_axis_line(object, 0.25, {640, 480});
      ASSERT_FALSE(sv::lines_agree(*a, *b, 3 * M_PI / 180, 6)) << "the other lines are not the object's";
    }
  // Nothing explored: the object's line as the fifth line counts, as the sixth it does not.
  for (const size_t before : {others.size(), others.size() + 1}) {
    SCOPED_TRACE(std::to_string(before) + " lines before the object's");
    sv::Supervisor s = make();
    s.start(now_, 100);
    s.on_services({}, now_);
    std::vector<Eigen::Vector3d> places = others;
    if (before > others.size()) places.push_back(first);
    places.push_back(object);
    hear(s, places);
    answer_survey(s, {object});
    if (before == others.size()) {
      EXPECT_EQ(s.state(), sv::State::SnapshotBefore) << s.report().reason;
    } else {
      EXPECT_EQ(s.state(), sv::State::Done) << s.report().reason;
      EXPECT_EQ(s.summary().rejections.count("not seen upright by both cameras (a stereo mismatch)"), 1u);
    }
  }
  // After the first object is segmented, its line ahead of the others is not counted: the object's
  // line, sixth, is the fifth of an unexplored object's.
  sv::Supervisor s = make();
  const Eigen::Vector3d rest = nudge_and_park(s, first);
  s.on_right_still(draw_scene(scene_, {1280, 960}, {rest}), now_, now_);
  ASSERT_EQ(outputs_of<sv::AttemptEnded>(s.take_outputs()).at(0).attempt->outcome, sv::Outcome::Segmented);
  ASSERT_EQ(s.state(), sv::State::FindCandidates);
  std::vector<Eigen::Vector3d> places = {rest};
  places.insert(places.end(), others.begin(), others.end());
  places.push_back(object);
  hear(s, places);
  answer_survey(s, {object});
  EXPECT_EQ(s.state(), sv::State::SnapshotBefore) << s.report().reason;
}

// A candidate that no frame of the survey shows as an upright axis in both cameras (seen 0%: the
// cameras see another object) is a stereo mismatch: passed over with its reason, not nudged.
TEST_F(SupervisorTest, ACandidateNeitherCameraShowsUprightIsNotNudged) {
  sv::Supervisor s = make();
  const Eigen::Vector3d object(0.24, 0.08, 0), mismatch(0.31, -0.06, 0);
  s.start(now_, 100);
  s.on_services({}, now_);
  hear_survey_lines(s, object, 10);
  now_ += kSecond;
  s.take_outputs();
  s.on_candidates({{0, mismatch, 20}}, now_, now_);
  EXPECT_EQ(s.state(), sv::State::Done);
  EXPECT_EQ(s.summary().rejections.count("not seen upright by both cameras (a stereo mismatch)"), 1u);
  EXPECT_NE(s.summary().end_reason.find("a stereo mismatch"), std::string::npos) << s.summary().end_reason;
  EXPECT_EQ(s.summary().attempts, 0);
}

TEST_F(SupervisorTest, ASnapshotThatNeverComesEndsTheAttemptAfterItsTimeout) {
  sv::Supervisor s = make();
  start_with(s, {Eigen::Vector3d(0.28, -0.05, 0)});
  s.on_time(now_ += 5 * kSecond);
  EXPECT_EQ(s.state(), sv::State::SnapshotBefore);
  s.on_right_still(draw_scene(scene_, {1280, 960}, {}), now_ - 8 * kSecond, now_);  // taken before the request
  EXPECT_EQ(s.state(), sv::State::SnapshotBefore);
  s.on_time(now_ += 6 * kSecond);
  const auto ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(ended[0].attempt->outcome, sv::Outcome::SnapshotLost);
  EXPECT_EQ(s.state(), sv::State::FindCandidates);
  EXPECT_THROW(s.on_right_still(cv::Mat(480, 640, CV_8UC3), now_, now_), std::invalid_argument);  // wrong size: named
}

// A candidate whose before still never came is tried once more (the still says nothing about the
// candidate: a busy camera lost it); lost a second time, it is passed over so that a camera that
// never answers cannot loop the run.
TEST_F(SupervisorTest, ACandidateWhoseBeforeStillWasLostIsTriedOnceMore) {
  sv::Supervisor s = make();
  const Eigen::Vector3d object(0.28, -0.05, 0);
  start_with(s, {object});
  ASSERT_EQ(s.state(), sv::State::SnapshotBefore);
  s.on_time(now_ += 11 * kSecond);
  ASSERT_EQ(outputs_of<sv::AttemptEnded>(s.take_outputs()).size(), 1u);
  answer_survey(s, {object + Eigen::Vector3d(0.003, 0, 0)});  // the same object, seen again
  EXPECT_EQ(s.state(), sv::State::SnapshotBefore) << "tried again";
  s.on_time(now_ += 11 * kSecond);
  const auto second = outputs_of<sv::AttemptEnded>(s.take_outputs());
  ASSERT_EQ(second.size(), 1u);
  EXPECT_EQ(second[0].attempt->outcome, sv::Outcome::SnapshotLost);
  answer_survey(s, {object});
  EXPECT_EQ(s.state(), sv::State::Done) << "lost twice: passed over";
  EXPECT_EQ(s.summary().attempts, 2);
}

// A still lost on the way (a dropped UDP fragment loses the whole 3.7 MB message) is asked for
// again every snapshot_retry_s until the step's timeout; the answer to a later request is taken.
TEST_F(SupervisorTest, AStillThatDoesNotComeIsAskedForAgainUntilTheTimeout) {
  sv::Supervisor s = make();
  const Eigen::Vector3d object(0.28, -0.05, 0);
  const int64_t start = now_;
  EXPECT_EQ(outputs_of<sv::SnapshotRequest>(start_with(s, {object})).size(), 1u);
  ASSERT_EQ(s.state(), sv::State::SnapshotBefore);
  s.on_time(now_ += 2 * kSecond);
  EXPECT_TRUE(outputs_of<sv::SnapshotRequest>(s.take_outputs()).empty()) << "within snapshot_retry_s (3 s)";
  s.on_time(now_ += 2 * kSecond);
  EXPECT_EQ(outputs_of<sv::SnapshotRequest>(s.take_outputs()).size(), 1u) << "4 s after the request: asked again";
  s.on_time(now_ += 2 * kSecond);
  EXPECT_TRUE(outputs_of<sv::SnapshotRequest>(s.take_outputs()).empty()) << "2 s after the second request";
  s.on_right_still(draw_scene(scene_, {1280, 960}, {object}), now_, now_);
  std::string reasons;
  for (const sv::StateReport& r : outputs_of<sv::StateReport>(s.take_outputs())) reasons += r.reason + "; ";
  EXPECT_EQ(s.state(), sv::State::Nudge) << "the answer to the second request: " << reasons;

  // Never answered: asked at 0, 4, 8 s; lost after 10 s, naming the requests.
  sv::Supervisor lost = make();
  now_ = start;
  start_with(lost, {object});
  ASSERT_EQ(lost.state(), sv::State::SnapshotBefore);
  int requests = 0;
  std::vector<sv::AttemptEnded> ended;
  for (int i = 0; i < 11 && ended.empty(); ++i) {
    lost.on_time(now_ += kSecond);
    const auto outputs = lost.take_outputs();
    requests += static_cast<int>(outputs_of<sv::SnapshotRequest>(outputs).size());
    ended = outputs_of<sv::AttemptEnded>(outputs);
  }
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(ended[0].attempt->outcome, sv::Outcome::SnapshotLost);
  EXPECT_NE(ended[0].attempt->reason.find("asked 3 times"), std::string::npos) << ended[0].attempt->reason;
  EXPECT_EQ(requests, 2) << "the two requests after the first";
}

// A clock that goes back an hour (the world or the log restarted) would leave the run waiting an
// hour for a snapshot; restarted, the timeout counts from the new time and the attempt ends.
TEST_F(SupervisorTest, AClockThatGoesBackRestartsTheTimeoutsInsteadOfWaitingForItToCatchUp) {
  sv::Supervisor s = make();
  start_with(s, {Eigen::Vector3d(0.28, -0.05, 0)});
  s.on_time(now_ += 5 * kSecond);
  ASSERT_EQ(s.state(), sv::State::SnapshotBefore);
  const int64_t back = now_ - 3600 * kSecond;
  s.on_time(back + 11 * kSecond);
  EXPECT_EQ(s.state(), sv::State::SnapshotBefore) << "a negative interval is no timeout";
  s.on_clock_restart(back);
  s.on_time(back + 5 * kSecond);
  EXPECT_EQ(s.state(), sv::State::SnapshotBefore);
  s.on_time(back + 11 * kSecond);
  const auto ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(ended[0].attempt->outcome, sv::Outcome::SnapshotLost);
}

TEST_F(SupervisorTest, AServiceDyingMidNudgeStopsTheArmPausesAndResumesWithASurvey) {
  sv::Supervisor s = make();
  const Eigen::Vector3d object(0.28, -0.05, 0);
  const sv::NudgeCommand nudge = nudge_command_for(s, object);
  s.on_arm_state(arm(sv::ArmStatus::Motion::Moving, nudge.seq), now_);
  s.on_services({"camera"}, now_ += kSecond);
  auto out = s.take_outputs();
  ASSERT_EQ(outputs_of<sv::StopCommand>(out).size(), 1u);
  EXPECT_EQ(s.state(), sv::State::Paused);
  EXPECT_NE(s.report().reason.find("camera"), std::string::npos);
  // Paused: time passes without timeouts firing, arm reports are not taken for the nudge's.
  s.on_time(now_ += 100 * kSecond);
  s.on_arm_state(arm(sv::ArmStatus::Motion::Done, nudge.seq), now_);
  EXPECT_EQ(s.state(), sv::State::Paused);
  s.on_services({}, now_ += kSecond);
  out = s.take_outputs();
  const auto ended = outputs_of<sv::AttemptEnded>(out);
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(ended[0].attempt->outcome, sv::Outcome::Aborted);
  EXPECT_EQ(outputs_of<sv::HomeCommand>(out).size(), 1u);  // the arm stopped somewhere: park it first
  park(s);
  EXPECT_EQ(outputs_of<sv::CandidatesRequest>(s.take_outputs()).size(), 1u);
  EXPECT_EQ(s.state(), sv::State::FindCandidates);
}

TEST_F(SupervisorTest, StaleAnswersAreIgnoredAndASilentTriangulationFailsTheRun) {
  sv::Supervisor s = make();
  s.start(now_, 1);
  EXPECT_EQ(s.state(), sv::State::FindCandidates);
  s.take_outputs();
  s.on_candidates({{0, Eigen::Vector3d(0.28, -0.05, 0), 9}}, now_ - kSecond, now_);  // from before the request
  EXPECT_EQ(s.state(), sv::State::FindCandidates);
  s.on_time(now_ += 61 * kSecond);
  EXPECT_EQ(s.state(), sv::State::Failed);
  EXPECT_NE(s.summary().end_reason.find("CANDIDATES"), std::string::npos);
}

TEST_F(SupervisorTest, SameInputsSameOutputs) {
  auto run = [&](std::vector<std::string>* trace) {
    now_ = 50 * kSecond;
    sv::Supervisor s = make();
    const Eigen::Vector3d object(0.28, -0.05, 0);
    const sv::NudgeCommand nudge = nudge_command_for(s, object);
    play_nudge(s, nudge.seq, object, object + 0.03 * nudge.direction);
    settle_with_axes(s, {object + 0.03 * nudge.direction});
    park(s);
    s.on_right_still(draw_scene(scene_, {1280, 960}, {object + 0.03 * nudge.direction}), now_, now_);
    for (const auto& report : outputs_of<sv::StateReport>(s.take_outputs()))
      trace->push_back(std::string(sv::to_string(report.state)) + ": " + report.reason);
  };
  std::vector<std::string> a, b;
  run(&a);
  run(&b);
  EXPECT_EQ(a, b);
  EXPECT_FALSE(a.empty());
}

// A nudge of the object at (0.28, -0.05): it starts to slide, then what the cameras see there keeps
// changing but has no symmetry left (a splash, a crumpling object): motion without a line, and the
// trackers give up. The settled AXES then say it stands 3 cm on. Returns the supervisor's outputs.
std::vector<sv::Output> SupervisorTest::slide_without_symmetry(sv::Supervisor& s) {
  const Eigen::Vector3d object(0.28, -0.05, 0);
  const sv::NudgeCommand nudge = nudge_command_for(s, object);
  s.on_arm_state(arm(sv::ArmStatus::Motion::Moving, nudge.seq), now_);
  cv::RNG rng(3);
  for (int i = -3; i <= 25; ++i) {
    now_ += kSecond / 10;
    const Eigen::Vector3d at = object + 0.004 * std::clamp(i, 0, 5) * nudge.direction;
    if (i <= 5) {
      show(s, {at});
      continue;
    }
    for (int camera = 0; camera < 2; ++camera) {
      cv::Mat frame = draw_scene(scene_, {640, 480}, {}, camera == 0);
      const auto p = camera == 0 ? scene_.project_left(at + Eigen::Vector3d(0, 0, 0.06), {640, 480})
                                 : scene_.project_right(at + Eigen::Vector3d(0, 0, 0.06), {640, 480});
      cv::Mat patch = frame(cv::Rect(cvRound(p->x) - 40, cvRound(p->y) - 50, 80, 100));
      rng.fill(patch, cv::RNG::UNIFORM, 0, 255);
      if (camera == 0) s.on_left_frame(frame, now_);
      else s.on_right_frame(frame, now_);
    }
  }
  s.on_arm_state(arm(sv::ArmStatus::Motion::Done, nudge.seq), now_);
  settle_with_axes(s, {object + 0.03 * nudge.direction});
  return s.take_outputs();
}

TEST_F(SupervisorTest, WhatTheTrackersSawDecidesNotTheSettledAxes) {
  sv::Config with_trackers = drawn_config();
  with_trackers.track = true;
  sv::Supervisor s = make(with_trackers);
  const auto out = slide_without_symmetry(s);  // AXES would say "fine": the trackers decide
  ASSERT_EQ(s.state(), sv::State::Home) << sv::to_string(s.state()) << ": " << s.report().reason;
  const auto ended = outputs_of<sv::AttemptEnded>(out);
  ASSERT_EQ(ended.size(), 1u);
  // Lost, or what they held no longer makes an upright axis: either way no segmentation.
  const sv::Outcome outcome = ended[0].attempt->outcome;
  EXPECT_TRUE(outcome == sv::Outcome::TrackerLost || outcome == sv::Outcome::Tipped) << ended[0].attempt->reason;
  EXPECT_TRUE(ended[0].attempt->after.empty());
}

// Traced only, the same trackers are watched (their per-frame states kept for the report's plot)
// while the settled AXES decide: the attempt goes on to the after still.
TEST_F(SupervisorTest, TracedTrackersAreKeptButTheSettledAxesDecide) {
  sv::Config traced = drawn_config();
  traced.track_trace = true;
  sv::Supervisor s = make(traced);
  const auto out = slide_without_symmetry(s);
  EXPECT_TRUE(outputs_of<sv::AttemptEnded>(out).empty()) << s.report().reason;
  ASSERT_EQ(s.state(), sv::State::Home) << s.report().reason;
  EXPECT_NE(s.report().reason.find("object at rest"), std::string::npos) << s.report().reason;
  s.on_arm_state(arm(sv::ArmStatus::Motion::Done, s.awaited_arm_seq()), now_ += kSecond);
  ASSERT_EQ(s.state(), sv::State::SnapshotAfter);
  s.on_right_still(draw_scene(scene_, {1280, 960}, {}), now_, now_);
  const auto ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
  ASSERT_EQ(ended.size(), 1u);
  const sv::Attempt& a = *ended[0].attempt;
  EXPECT_GT(a.track_trace[0].size(), 10u);
  EXPECT_GT(a.track_trace[1].size(), 10u);
  EXPECT_FALSE(a.tracked[0] || a.tracked[1]) << "the trackers' lines decided nothing";

}

TEST_F(SupervisorTest, MotionFarAboveTheObjectIsNotKeptInItsMask) {
  // A segmentation that also marks something moving high up the line (an arm, a hand).
  auto with_arm = [](const cv::Mat& before, const cv::Mat& after, const nudge::symmetry::Line& l0,
                     const nudge::symmetry::Line& l1) {
    sv::Segmentation s = mask_of_difference(before, after, l0, l1);
    s.mask(cv::Rect(600, 10, 80, 60)).setTo(255);
    return s;
  };
  sv::Supervisor s(drawn_config(), scene_, sv::ArmSetup{}, with_arm);
  const Eigen::Vector3d object(0.28, -0.05, 0);
  const Eigen::Vector3d rest = nudge_and_park(s, object);
  ASSERT_EQ(s.state(), sv::State::SnapshotAfter);
  s.on_right_still(draw_scene(scene_, {1280, 960}, {rest}), now_, now_);
  const auto ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
  ASSERT_EQ(ended.size(), 1u);
  const cv::Mat& mask = ended[0].attempt->segmentation.mask;
  EXPECT_EQ(cv::countNonZero(mask(cv::Rect(600, 10, 80, 60))), 0) << "the high blob is gone";
  EXPECT_GT(cv::countNonZero(mask), 1000) << "the object stays";
}

// A neighbour pushed along with the object moves rigidly with it and is attached to its mask
// (development m02: a bottle's mask with the mug beside it, IoU 0.42-0.55). Nothing of an
// upright object lies farther from its line than the widest object's half-width (a mug's handle,
// 7.5 cm): what does is cleared, and the attempt counts the pixels.
TEST_F(SupervisorTest, MotionBesideTheObjectBeyondTheWidestObjectIsNotKeptInItsMask) {
  cv::Rect object_box, neighbour;
  cv::Mat object_mask;
  auto with_neighbour = [&](const cv::Mat& before, const cv::Mat& after, const nudge::symmetry::Line& l0,
                            const nudge::symmetry::Line& l1) {
    sv::Segmentation s = mask_of_difference(before, after, l0, l1);
    object_mask = s.mask.clone();
    object_box = cv::boundingRect(s.mask);
    // A neighbour joined to the object's right side, 300 px wide, over the object's lowest fifth.
    neighbour = cv::Rect(object_box.br().x, object_box.br().y - object_box.height / 5, 300, object_box.height / 5);
    s.mask(neighbour).setTo(255);
    return s;
  };
  const sv::Attempt a = attempt_segmented_by(with_neighbour);
  ASSERT_EQ(a.outcome, sv::Outcome::Segmented) << a.reason;
  const cv::Mat& mask = a.segmentation.mask;
  EXPECT_EQ(cv::countNonZero(mask(cv::Rect(neighbour.x + 200, neighbour.y, 100, neighbour.height))), 0)
      << "the neighbour's far part is gone";
  EXPECT_EQ(cv::countNonZero(object_mask & ~mask), 0) << "the object's own pixels stay";
  EXPECT_GT(a.mask_pixels_beside, 200 * neighbour.height) << "the cleared pixels are counted";

  // Turned off, the neighbour stays, and the mask is too lopsided to be an object's.
  sv::Config keep = drawn_config();
  keep.max_object_half_width_m = 0;
  sv::Supervisor s(keep, scene_, sv::ArmSetup{}, with_neighbour);
  const Eigen::Vector3d rest = nudge_and_park(s, Eigen::Vector3d(0.28, -0.05, 0));
  s.on_right_still(draw_scene(scene_, {1280, 960}, {rest}), now_, now_);
  const auto ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(cv::countNonZero(ended[0].attempt->segmentation.mask(neighbour)), neighbour.area());
  EXPECT_EQ(ended[0].attempt->outcome, sv::Outcome::SegmentationFailed) << ended[0].attempt->reason;
}

// A few hundred pixels of motion (a cup's mask has ~20 000 in the still) are no object: the
// attempt fails with its reason rather than reporting a segmentation of nothing (held-out hm1).
TEST_F(SupervisorTest, AMaskTooSmallForAnyObjectIsNoSegmentation) {
  auto speck = [](const cv::Mat& before, const cv::Mat& after, const nudge::symmetry::Line& l0, const nudge::symmetry::Line& l1) {
    sv::Segmentation s = mask_of_difference(before, after, l0, l1);
    cv::Rect box = cv::boundingRect(s.mask);
    s.mask.setTo(0);
    s.mask(cv::Rect(box.x, box.y + box.height - 20, std::min(box.width, 35), 20)).setTo(255);  // 700 px at its foot
    return s;
  };
  const sv::Attempt a = attempt_segmented_by(speck);
  EXPECT_EQ(a.outcome, sv::Outcome::SegmentationFailed);
  EXPECT_NE(a.reason.find("too small for an object"), std::string::npos) << a.reason;
}

// A sliver a few rows tall (development m02: 3720 px along a table edge after a push that moved a
// mug behind a bottle) or a few pixels wide (second held-out set h06: 2649 px along a mug's edge)
// is as large as a small object but no object's shape: no segmentation.
TEST_F(SupervisorTest, AMaskOnlyAFewRowsTallOrPixelsWideIsNoSegmentation) {
  for (const bool flat : {true, false}) {
    SCOPED_TRACE(flat ? "8 rows tall" : "10 px wide");
    auto sliver = [flat](const cv::Mat& before, const cv::Mat& after, const nudge::symmetry::Line& l0, const nudge::symmetry::Line& l1) {
      sv::Segmentation s = mask_of_difference(before, after, l0, l1);
      const cv::Rect box = cv::boundingRect(s.mask);
      s.mask.setTo(0);
      if (flat) s.mask(cv::Rect(box.x, box.y + box.height - 8, 600, 8)).setTo(255);  // 4800 px at its foot
      else s.mask(cv::Rect(box.x + box.width / 2, box.y, 10, box.height)).setTo(255);  // 1580 px down its middle
      return s;
    };
    const sv::Attempt a = attempt_segmented_by(sliver);
    EXPECT_EQ(a.outcome, sv::Outcome::SegmentationFailed);
    EXPECT_NE(a.reason.find(flat ? "too flat for an object" : "too thin for an object"), std::string::npos) << a.reason;
  }
}

// The mask of an upright symmetric object is symmetric about its line in the after still; one
// that is not is a piece of something (development m02: a 6507 px piece of a cup that barely
// moved, IoU 0.15, agreeing 0.32 with its mirror image).
TEST_F(SupervisorTest, AMaskNotSymmetricAboutTheObjectsLineIsNoSegmentation) {
  auto one_side = [](const cv::Mat& before, const cv::Mat& after, const nudge::symmetry::Line& l0, const nudge::symmetry::Line& l1) {
    sv::Segmentation s = mask_of_difference(before, after, l0, l1);
    const cv::Rect box = cv::boundingRect(s.mask);
    s.mask.colRange(0, box.x + box.width / 2).setTo(0);  // the half right of the line only
    return s;
  };
  const sv::Attempt a = attempt_segmented_by(one_side);
  EXPECT_EQ(a.outcome, sv::Outcome::SegmentationFailed);
  EXPECT_NE(a.reason.find("not symmetric about the object's line"), std::string::npos) << a.reason;
  // The whole (symmetric) mask of the same push is a segmentation.
  EXPECT_EQ(attempt_segmented_by(mask_of_difference).outcome, sv::Outcome::Segmented);
}

// With the side-edge check on (--min-mask-side-edges; off by default since it refused masks of the
// object as often as wrong ones), a mask symmetric about the object's line whose sides leave the
// object's outline is no segmentation: cut about a wrong line (development m02: half a red cup, its right side inside the
// cup) or, as here, spilling past both sides of the object onto the table. The masks of
// mask_of_difference span both places of the object: cut here to the after still's object first.
TEST_F(SupervisorTest, AMaskWhoseSidesLeaveTheObjectsOutlineIsNoSegmentation) {
  auto cut_to_the_object = [](const cv::Mat& before, const cv::Mat& after, const nudge::symmetry::Line& l0,
                              const nudge::symmetry::Line& l1) {
    sv::Segmentation s = mask_of_difference(before, after, l0, l1);
    cv::Mat from_table, off;
    cv::absdiff(after, drawn_background(after.size()), from_table);
    cv::transform(from_table, off, cv::Matx13f(1, 1, 1));
    s.mask &= off > 20;
    return s;
  };
  auto spilled = [&](const cv::Mat& before, const cv::Mat& after, const nudge::symmetry::Line& l0, const nudge::symmetry::Line& l1) {
    sv::Segmentation s = cut_to_the_object(before, after, l0, l1);
    cv::dilate(s.mask, s.mask, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(61, 1)));  // 30 px each side
    return s;
  };
  sv::Config checked;  // the check on, as --min-mask-side-edges 0.2 sets it (off by default)
  EXPECT_EQ(checked.min_mask_side_edges, 0);
  checked.min_mask_side_edges = 0.2;
  const sv::Attempt a = attempt_segmented_by(spilled, checked);
  EXPECT_EQ(a.outcome, sv::Outcome::SegmentationFailed);
  EXPECT_NE(a.reason.find("sides leave the object's outline"), std::string::npos) << a.reason;
  const sv::Attempt whole = attempt_segmented_by(cut_to_the_object, checked);
  EXPECT_EQ(whole.outcome, sv::Outcome::Segmented) << whole.reason;
}

// A mug's handle moves its symmetry line differently in the two cameras: the settled axes lie
// several cm nearer or farther along the right camera's ray than the mug stands (s03_red_mug:
// 4.7 cm). They are still the pushed object, and its mask keeps the rows down to its real foot.
TEST_F(SupervisorTest, AxesOffInDepthAlongTheCamerasRayAreStillThePushedObject) {
  const NudgedAlongRay run = nudge_and_settle_along_ray({0.05});  // 5 cm too far: more than the 3 cm off the push line
  ASSERT_EQ(run.state, sv::State::SnapshotAfter) << run.reason;
  const auto& ended = run.ended;
  const Eigen::Vector3d& rest = run.rest;
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(ended[0].attempt->outcome, sv::Outcome::Segmented) << ended[0].attempt->reason;
  // The rows just above the real foot are in the mask (the rest 5 cm farther would cut them).
  const cv::Mat& mask = ended[0].attempt->segmentation.mask;
  const int foot_row = static_cast<int>(scene_.project_right(rest, {1280, 960})->y);
  EXPECT_GT(cv::countNonZero(mask.rowRange(foot_row - 12, foot_row - 2)), 100) << "the object's foot is kept";
}

// The depth tolerance lets axes further along the ray into the window (another object, a phantom):
// the pushed object is the group of axes nearest the push line, not the median of everything.
TEST_F(SupervisorTest, AxesOfSomethingElseFurtherAlongTheRayDoNotMoveTheRest) {
  // Per frame: the object's axis, and two axes of something 7 cm behind it along the ray.
  const NudgedAlongRay run = nudge_and_settle_along_ray({0.0, 0.07, 0.072});
  ASSERT_EQ(run.state, sv::State::SnapshotAfter) << run.reason;
  const auto& ended = run.ended;
  const Eigen::Vector3d& rest = run.rest;
  ASSERT_EQ(ended.size(), 1u);
  ASSERT_TRUE(ended[0].attempt->rest.has_value());
  EXPECT_LT((*ended[0].attempt->rest - rest).norm(), 0.005) << "rested at the object's own axes";
}

// Something standing behind the object in line with it in the right camera (the arm's base
// column: held-out h09) pairs with the object's left line into settled axes off in depth, on the
// line the object stood on: the after line is predicted and found there, where nothing moved. A
// push runs across the right camera's view, so the object is looked for along the push instead.
TEST_F(SupervisorTest, AnAfterLineWhereNothingMovedGivesWayToTheObjectsAlongThePush) {
  const Eigen::Vector3d object(0.28, -0.05, 0);
  auto run = [&](double push_travel_m) {
    sv::Config config = drawn_config();
    config.push_travel_m = push_travel_m;
    sv::Supervisor s = make(config);
    const sv::NudgeCommand nudge = nudge_command_for(s, object);
    const Eigen::Vector3d rest = object + 0.10 * nudge.direction;  // clear of what stands there
    // What stands in line with the object stays in the right camera's view where the object stood
    // (drawn as an object of the same shape), and its line pairs with the object's left one into
    // settled axes 5 cm off in depth, every frame.
    play_nudge(s, nudge.seq, object, rest, {object});
    settle_with_axes(s, {object + 0.05 * along_ray(object)});
    const auto attempt = park_and_show_after_still_of(s, {rest, object});
    EXPECT_TRUE(attempt && attempt->after_line);
    return std::make_pair(attempt, rest);
  };
  const auto [searched, rest] = run(0.09);
  const auto not_searched = run(0).first;
  ASSERT_TRUE(searched && searched->after_line && not_searched && not_searched->after_line);
  const auto rest_line = scene_.right_axis_line(rest, 0.25, {1280, 960});
  const auto before_line = scene_.right_axis_line(object, 0.25, {1280, 960});
  ASSERT_TRUE(rest_line && before_line);
  EXPECT_EQ(searched->outcome, sv::Outcome::Segmented) << searched->reason;
  // (The detected lines lean a little off the predictions: within 10 px at the image's centre.)
  EXPECT_LT(std::abs(searched->after_line->r - rest_line->r), 10) << "the object's line where the push took it";
  EXPECT_LT(std::abs(not_searched->after_line->r - before_line->r), 10) << "without the search: the standing line";
}

// An object that barely slid along the push line keeps its line in the after still: the search
// along the push is for a rest off the line in depth only (held-out hm3: a cup pushed 5 mm, and a
// neighbour where the search would look).
TEST_F(SupervisorTest, AnObjectThatBarelySlidKeepsItsLineWhateverStandsAlongThePush) {
  const Eigen::Vector3d object(0.28, -0.05, 0);
  sv::Config config = drawn_config();
  config.push_travel_m = 0.10;  // where the neighbour stands, clear of the object
  sv::Supervisor s = make(config);
  const sv::NudgeCommand nudge = nudge_command_for(s, object);
  const Eigen::Vector3d rest = object + 0.0045 * nudge.direction;  // its line moves less than the 8 px of "the same line"
  const Eigen::Vector3d neighbour = object + config.push_travel_m * nudge.direction;
  play_nudge(s, nudge.seq, object, rest, {neighbour});
  settle_with_axes(s, {rest});
  const auto attempt = park_and_show_after_still_of(s, {neighbour, rest});
  ASSERT_TRUE(attempt && attempt->after_line);
  const auto rest_line = scene_.right_axis_line(rest, 0.25, {1280, 960});
  ASSERT_TRUE(rest_line);
  EXPECT_LT(std::abs(attempt->after_line->r - rest_line->r), 10);
}

// A neighbour standing far along the push, its axes seen only once the pushed object moved aside,
// is the only settled group near the push line (held-out hm3: a water bottle pushed 2 cm was
// "placed" on a clear bottle's axes 10 cm along the push). Nothing changed about its line between
// the stills, so the object is looked for as a new line along the push, and found.
TEST_F(SupervisorTest, AFarRestWhereNothingChangedGivesWayToTheObjectsNewLineAlongThePush) {
  const Eigen::Vector3d object(0.28, -0.05, 0);
  auto run = [&](double far_rest_m) {
    sv::Config config = drawn_config();
    config.far_rest_m = far_rest_m;
    sv::Supervisor s = make(config);
    const auto [nudge, neighbour] = nudge_command_with_neighbour_along(s, config, object, 0.10);
    const Eigen::Vector3d rest = object + 0.02 * nudge.direction;
    play_nudge(s, nudge.seq, object, rest, {neighbour});
    settle_with_axes(s, {neighbour});
    const auto attempt = park_and_show_after_still_of(s, {rest, neighbour});
    return std::make_tuple(attempt, rest, neighbour);
  };
  const auto [searched, rest, neighbour] = run(sv::Config{}.far_rest_m);
  ASSERT_TRUE(searched && searched->rest);
  EXPECT_EQ(searched->outcome, sv::Outcome::Segmented) << searched->reason;
  EXPECT_TRUE(searched->rest_from_still);
  EXPECT_LT((*searched->rest - rest).norm(), 0.005);
  ASSERT_TRUE(searched->rest_from_axes);
  EXPECT_LT((*searched->rest_from_axes - neighbour).norm(), 0.005) << "the replaced rest: the neighbour's axes";
  const auto kept = std::get<0>(run(0));
  ASSERT_TRUE(kept && kept->rest);
  EXPECT_FALSE(kept->rest_from_still);
  EXPECT_GT((*kept->rest - rest).norm(), 0.05) << "without the check the neighbour's axes place it";
}

// The settled axes are a small neighbour's, standing behind the pushed object in both stills (a
// stereo mismatch or another thing's axes: held-out h03's cup, its after line 19 votes against 123
// before, 40 px off). The line found about them is the neighbour's, with few of the before line's
// votes: the object is looked for as a new line along the push instead, and found.
TEST_F(SupervisorTest, AWeakAfterLineAboutTheSettledAxesGivesWayToAStrongerOneAlongThePush) {
  const Eigen::Vector3d object(0.28, -0.05, 0);
  const Shape small{0.025, 0.022};
  auto run = [&](double weak_share) {
    sv::Config config = drawn_config();
    config.weak_after_line_share = weak_share;
    // The rest as the stills' lines place it: the drawn objects' masks (flat outlines, the small
    // one half behind the other) show no cylinder's base to check it against.
    config.rest_mask_disagreement_m = 0;
    sv::Supervisor probe = make(config);
    const Eigen::Vector3d direction = nudge_command_for(probe, object).direction;
    // Behind where it stood and to one side, off the push line in depth: the nearest group of
    // settled axes, though not on the push line.
    const Eigen::Vector3d neighbour = object - 0.025 * direction + 0.06 * along_ray(object);
    sv::Supervisor s = make(config);
    start_with(s, {object});
    s.on_right_still(draw_scene(scene_, {1280, 960}, {neighbour, object}, false, {small, Shape{}}), now_, now_);
    const sv::NudgeCommand nudge = outputs_of<sv::NudgeCommand>(s.take_outputs()).at(0);
    const Eigen::Vector3d rest = object + 0.025 * nudge.direction;
    play_nudge(s, nudge.seq, object, rest, {neighbour});
    settle_with_axes(s, {neighbour});
    const auto attempt = park_and_show_after_still_of(s, {neighbour, rest}, {small, Shape{}});
    return std::make_tuple(attempt, rest, neighbour);
  };
  const auto [searched, rest, neighbour] = run(sv::Config{}.weak_after_line_share);
  ASSERT_TRUE(searched && searched->rest && searched->before_line && searched->after_line);
  EXPECT_EQ(searched->outcome, sv::Outcome::Segmented) << searched->reason;
  EXPECT_TRUE(searched->rest_from_still);
  EXPECT_LT((*searched->rest - rest).norm(), 0.005) << "placed where the push took it";
  ASSERT_TRUE(searched->rest_from_axes && searched->weak_after_line_votes);
  EXPECT_LT((*searched->rest_from_axes - neighbour).norm(), 0.005) << "the replaced rest: the neighbour's axes";
  EXPECT_LT(*searched->weak_after_line_votes, 0.25 * searched->before_line->votes);
  EXPECT_GT(searched->after_line->votes, *searched->weak_after_line_votes);
  const auto kept = std::get<0>(run(0));
  ASSERT_TRUE(kept && kept->rest);
  EXPECT_FALSE(kept->rest_from_still);
  EXPECT_FALSE(kept->weak_after_line_votes);
  EXPECT_LT((*kept->rest - neighbour).norm(), 0.005) << "without the check the neighbour's axes place it";
}

// The settled group holds more than the object's axis: frames it still slid in, and its lines
// mismatched with others' (leaning 8-15 deg, 1-2 cm off). The rest is where the axes repeat: the
// learning test's cup otherwise rested 7-16 mm off, leaning 10 deg, and the grasp missed it.
TEST_F(SupervisorTest, TheRestIsWhereTheSettledAxesRepeatNotTheMedianOfTheirGroup) {
  sv::Supervisor s = make();
  const Eigen::Vector3d rest = push_until_settling(s);
  const Eigen::Vector3d along = (rest - Eigen::Vector3d(0.28, -0.05, 0)).normalized();
  const Eigen::Vector3d across(-along.y(), along.x(), 0);
  const double upright = 1 * M_PI / 180;
  std::mt19937 random(7);
  auto uniform = [&](double low, double high) { return std::uniform_real_distribution<double>(low, high)(random); };
  for (int frame = 0; frame < 20 && s.state() == sv::State::Track; ++frame) {
    now_ += kSecond / 10;
    show(s, {rest});
    // Still sliding in the first frames the settling time counts (from 0.5 s on).
    const double short_of_rest = std::max(0.0, 0.004 * (7 - frame));
    std::vector<sv::Axis> axes{{rest - short_of_rest * along, upright}};
    // Two mismatched pairings a frame, 0.5-2.5 cm beyond the object (lines of something farther on).
    for (int k = 0; k < 2; ++k)
      axes.push_back({rest + uniform(0.005, 0.025) * along + uniform(-0.01, 0.01) * across, uniform(7, 15) * M_PI / 180});
    s.on_axes(axes, now_, now_);
    s.on_time(now_);
  }
  const auto attempt = park_and_show_after_still(s, rest);
  ASSERT_TRUE(attempt && attempt->rest && attempt->rest_tilt_deg);
  EXPECT_LT((*attempt->rest - rest).norm(), 0.002);
  EXPECT_LT(*attempt->rest_tilt_deg, 2.0) << "the object's own axis leans 1 deg";
}

// Settled axes that agree among themselves but stand 5 cm behind the object along the ray (one
// camera's line paired with another line, every frame: the white bottle's) give way to the foot
// of the after still's mask; 1.5 cm off, they stay (the mask's foot errs that much: the table's
// shadow under the object lowers its front).
TEST_F(SupervisorTest, AStableMismatchAlongTheRayGivesWayToTheMasksFoot) {
  for (const double behind : {0.05, 0.025, 0.015}) {
    const Eigen::Vector3d object(0.28, -0.05, 0);
    Eigen::Vector3d truth = object;
    auto segment_cylinder = [&](const cv::Mat&, const cv::Mat& after, const nudge::symmetry::Line&, const nudge::symmetry::Line&) {
      sv::Segmentation out;
      out.mask = cylinder_mask(scene_, after.size(), truth, 0.035, 0.12);
      return out;
    };
    sv::Supervisor s(drawn_config(), scene_, sv::ArmSetup{}, segment_cylinder);
    const sv::NudgeCommand nudge = nudge_command_for(s, object);
    truth = object + 0.03 * nudge.direction;
    const Eigen::Vector3d ray = along_ray(truth);
    play_nudge(s, nudge.seq, object, truth);
    settle_with_axes(s, {truth + behind * ray});
    const auto attempt = park_and_show_after_still(s, truth);
    ASSERT_TRUE(attempt);
    const sv::Attempt& a = *attempt;
    ASSERT_TRUE(a.rest && a.rest_from_mask) << a.reason;
    EXPECT_LT((*a.rest_from_mask - truth).norm(), 0.005);
    if (behind > 0.02) {
      EXPECT_LT((*a.rest - truth).norm(), 0.005) << "the mask's foot";
      ASSERT_TRUE(a.rest_from_axes);
      EXPECT_LT((*a.rest_from_axes - (truth + behind * ray)).norm(), 0.002);
    } else {
      EXPECT_LT((*a.rest - (truth + behind * ray)).norm(), 0.002) << "the axes' rest stays";
      EXPECT_FALSE(a.rest_from_axes);
    }
  }
}

// The object nudged is remembered where it now stands: a candidate that is the same object seen
// through a stereo mismatch (on its line in one camera, 8 cm farther) is not nudged again, while
// a candidate as far away but off both cameras' lines is.
TEST_F(SupervisorTest, ACandidateOnTheRestedObjectsLineInACameraIsThatObjectNotNudgedAgain) {
  sv::Supervisor s = make();
  const Eigen::Vector3d object(0.28, -0.05, 0);
  const Eigen::Vector3d rest = nudge_and_park(s, object);
  s.on_right_still(draw_scene(scene_, {1280, 960}, {rest}), now_, now_);
  ASSERT_EQ(outputs_of<sv::AttemptEnded>(s.take_outputs()).at(0).attempt->outcome, sv::Outcome::Segmented);
  Eigen::Vector3d ray = rest - scene_.right_camera_in_world();
  ray.z() = 0;
  ray.normalize();
  const Eigen::Vector3d mate = rest + 0.08 * ray;  // 8 cm farther from the camera on its ray
  auto out = answer_survey(s, {mate});
  EXPECT_EQ(s.state(), sv::State::Done) << s.report().reason;
  EXPECT_EQ(s.summary().rejections.count("already explored"), 1u) << "passed over as the same object, not as out of reach";
  EXPECT_TRUE(outputs_of<sv::SnapshotRequest>(out).empty());
  // Another object as far from it, beside it (off both cameras' lines): nudged.
  sv::Supervisor t = make();
  start_with(t, {object});
  t.on_right_still(draw_scene(scene_, {1280, 960}, {object}), now_, now_);
  const auto second = outputs_of<sv::NudgeCommand>(t.take_outputs()).at(0);
  play_nudge(t, second.seq, object, rest);
  settle_with_axes(t, {rest});
  park(t);
  t.on_right_still(draw_scene(scene_, {1280, 960}, {rest}), now_, now_);
  t.take_outputs();
  // (On the side where its push away from the object at rest, an obstacle now, stays in reach.)
  const Eigen::Vector3d beside = rest - 0.08 * Eigen::Vector3d(-ray.y(), ray.x(), 0);
  out = answer_survey(t, {beside});
  EXPECT_EQ(t.state(), sv::State::SnapshotBefore) << t.report().reason;
}

// A push whose segmentation comes out empty leaves its place explored, but nothing is known to
// stand there: its lines stay in later surveys and what stands on them is nudged (development m03:
// a phantom's push barely moved a neighbour, and leaving out the phantom's lines - the cup's and
// the bottle's - left the cup no candidate again).
TEST_F(SupervisorTest, AFailedSegmentationsRestIsNoObjectToLeaveOut) {
  sv::Supervisor s(drawn_config(), scene_, sv::ArmSetup{}, segment_nothing);
  const Eigen::Vector3d object(0.28, -0.05, 0);
  const Eigen::Vector3d rest = nudge_and_park(s, object);
  s.on_right_still(draw_scene(scene_, {1280, 960}, {rest}), now_, now_);
  const auto out = s.take_outputs();
  ASSERT_EQ(outputs_of<sv::AttemptEnded>(out).at(0).attempt->outcome, sv::Outcome::SegmentationFailed);
  const auto surveys = outputs_of<sv::CandidatesRequest>(out);
  ASSERT_EQ(surveys.size(), 1u);
  EXPECT_TRUE(surveys[0].explored.empty());
  // On its line in the right camera, 8 cm farther: not taken for the place nudged.
  answer_survey(s, {rest + 0.08 * along_ray(rest)});
  EXPECT_EQ(s.state(), sv::State::SnapshotBefore) << s.report().reason;
}

// A push that moves the object but gives no segmentation leaves its rest to be nudged again, once
// (Config::segmentation_retries): a second failure there leaves the new rest explored. With no
// retries the first rest is explored at once (held-out h11: a clear bottle's lopsided first mask).
TEST_F(SupervisorTest, AnObjectWhoseSegmentationFailedIsNudgedAgainFromItsRestOnce) {
  for (const int retries : {1, 0}) {
    SCOPED_TRACE("segmentation_retries " + std::to_string(retries));
    sv::Config config = drawn_config();
    config.segmentation_retries = retries;
    sv::Supervisor s(config, scene_, sv::ArmSetup{}, segment_nothing);
    const Eigen::Vector3d object(0.28, -0.05, 0);
    const Eigen::Vector3d rest = nudge_and_park(s, object);
    s.on_right_still(draw_scene(scene_, {1280, 960}, {rest}), now_, now_);
    const auto first = outputs_of<sv::AttemptEnded>(s.take_outputs());
    ASSERT_EQ(first.at(0).attempt->outcome, sv::Outcome::SegmentationFailed);
    answer_survey(s, {rest});
    if (retries == 0) {
      EXPECT_EQ(s.state(), sv::State::Done) << s.report().reason;
      EXPECT_EQ(s.summary().rejections.count("already explored"), 1u);
      continue;
    }
    EXPECT_NE(first.at(0).attempt->reason.find("nudged again"), std::string::npos) << first.at(0).attempt->reason;
    ASSERT_EQ(s.state(), sv::State::SnapshotBefore) << s.report().reason;
    EXPECT_LT((s.report().target - rest).norm(), 1e-9);
    // The second push, from the rest, fails too: its rest is explored.
    s.on_right_still(draw_scene(scene_, {1280, 960}, {rest}), now_, now_);
    const sv::NudgeCommand nudge = outputs_of<sv::NudgeCommand>(s.take_outputs()).at(0);
    const Eigen::Vector3d second_rest = rest + 0.03 * nudge.direction;
    play_nudge(s, nudge.seq, rest, second_rest);
    settle_with_axes(s, {second_rest});
    park(s);
    s.on_right_still(draw_scene(scene_, {1280, 960}, {second_rest}), now_, now_);
    const auto second = outputs_of<sv::AttemptEnded>(s.take_outputs());
    ASSERT_EQ(second.at(0).attempt->outcome, sv::Outcome::SegmentationFailed);
    EXPECT_EQ(second.at(0).attempt->reason.find("nudged again"), std::string::npos) << second.at(0).attempt->reason;
    answer_survey(s, {second_rest});
    EXPECT_EQ(s.state(), sv::State::Done) << s.report().reason;
    EXPECT_EQ(s.summary().rejections.count("already explored"), 1u);
  }
  sv::Config bad = drawn_config();
  bad.segmentation_retries = -1;
  EXPECT_THROW(sv::Supervisor(bad, scene_, sv::ArmSetup{}, segment_nothing), std::invalid_argument);
}

// Config::refine_target_max_m: a survey's place 3 cm off its object along the right camera's ray
// (a label's edges pull the two cameras' lines apart) is placed anew from the object's lines in
// both before stills, and the push is planned there; off, or with the left still missing, the
// survey's place is pushed. A place farther than the bound (another object's lines) is not taken.
TEST_F(SupervisorTest, TheTargetIsPlacedAnewFromItsLinesInBothBeforeStills) {
  const Eigen::Vector3d object(0.28, -0.05, 0);
  const Eigen::Vector3d surveyed = object + 0.03 * along_ray(object);
  struct Case {
    double max_m;
    bool left_still;
    bool placed_anew;
  };
  for (const Case& c : {Case{0.05, true, true}, Case{0.0, true, false}, Case{0.02, true, false}, Case{0.05, false, false}}) {
    SCOPED_TRACE("refine_target_max_m " + std::to_string(c.max_m) + (c.left_still ? "" : ", no left still"));
    sv::Config config = drawn_config();
    config.refine_target_max_m = c.max_m;
    sv::Supervisor s = make(config);
    const auto survey = start_with(s, {surveyed});
    const auto requests = outputs_of<sv::SnapshotRequest>(survey);
    ASSERT_EQ(requests.size(), 1u);
    EXPECT_EQ(requests[0].both, c.max_m > 0) << "the left before still is asked for only to place the target anew";
    s.on_right_still(draw_scene(scene_, {1280, 960}, {object}), now_, now_);
    if (c.max_m > 0 && c.left_still) {
      EXPECT_EQ(s.state(), sv::State::SnapshotBefore) << "waits for the left still";
      s.on_left_still(draw_scene(scene_, {1280, 960}, {object}, true), now_, now_);
    } else if (c.max_m > 0) {
      for (int i = 0; i < 200 && s.state() == sv::State::SnapshotBefore; ++i) s.on_time(now_ += kSecond / 10);
    }
    const auto nudges = outputs_of<sv::NudgeCommand>(s.take_outputs());
    ASSERT_EQ(nudges.size(), 1u) << s.report().reason;
    const double off = (nudges[0].target - object).head<2>().norm();
    if (c.placed_anew) {
      EXPECT_LT(off, 0.01);
      const Eigen::Vector3d ray = along_ray(nudges[0].target);
      EXPECT_NEAR(nudges[0].direction.head<2>().dot(ray.head<2>()), 0.0, 1e-6) << "across the ray at the new place";
    } else {
      EXPECT_NEAR((nudges[0].target - surveyed).norm(), 0.0, 1e-9);
    }
  }
  sv::Config bad = drawn_config();
  bad.refine_target_max_m = -0.01;
  EXPECT_THROW(make(bad), std::invalid_argument);
}

// An empty segmentation where the target's line stood still in the stills (Config::
// retry_still_line_px): something moved during the push, but not what stands at the target, so the
// place is not pushed again; with the check off it is (second development set's hm3: a phantom
// pushed twice).
TEST_F(SupervisorTest, AnEmptySegmentationWhoseLineStoodStillIsNotNudgedAgain) {
  for (const double still_px : {2.0, 0.0}) {
    SCOPED_TRACE("retry_still_line_px " + std::to_string(still_px));
    sv::Config config = drawn_config();
    config.retry_still_line_px = still_px;
    sv::Supervisor s(config, scene_, sv::ArmSetup{}, segment_nothing);
    const Eigen::Vector3d object(0.28, -0.05, 0);
    const sv::NudgeCommand nudge = nudge_command_for(s, object);
    play_nudge(s, nudge.seq, object, object + 0.03 * nudge.direction);  // motion seen while the arm pushed
    settle_with_axes(s, {object + 0.005 * nudge.direction});  // yet it settles 5 mm on, and the still
                                                             // shows its line where it stood
    park(s);
    s.on_right_still(draw_scene(scene_, {1280, 960}, {object}), now_, now_);
    const auto ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
    ASSERT_EQ(ended.at(0).attempt->outcome, sv::Outcome::SegmentationFailed) << ended.at(0).attempt->reason;
    const std::string& reason = ended.at(0).attempt->reason;
    answer_survey(s, {object});
    if (still_px > 0) {
      EXPECT_NE(reason.find("its line stood still"), std::string::npos) << reason;
      EXPECT_EQ(reason.find("will be nudged again"), std::string::npos) << reason;
      EXPECT_EQ(s.state(), sv::State::Done) << s.report().reason;
      EXPECT_EQ(s.summary().rejections.count("already explored"), 1u);
    } else {
      EXPECT_NE(reason.find("its rest will be nudged again"), std::string::npos) << reason;
      EXPECT_EQ(s.state(), sv::State::SnapshotBefore) << s.report().reason;
    }
  }
  sv::Config bad = drawn_config();
  bad.retry_still_line_px = -1;
  EXPECT_THROW(sv::Supervisor(bad, scene_, sv::ArmSetup{}, segment_nothing), std::invalid_argument);
}

// A striped object's other lines pair into candidates off its axis at other depths: one whose line
// in the right camera runs through the segmented object's mask is that object (development s06:
// the striped bottle nudged twice), one beside it is not.
TEST_F(SupervisorTest, ACandidateWhoseLineCrossesASegmentedObjectIsThatObjectNotNudgedAgain) {
  const Eigen::Vector3d object(0.28, -0.05, 0);
  for (const bool on_the_object : {true, false}) {
    SCOPED_TRACE(on_the_object ? "its line crosses the object's mask" : "its line passes beside it");
    // A segmentation that is the whole object where it rests (the difference marks only the
    // edges of the drawing's flat bands).
    const cv::Mat empty_table = draw_scene(scene_, {1280, 960}, {});
    sv::Supervisor s(drawn_config(), scene_, sv::ArmSetup{}, [&](const cv::Mat&, const cv::Mat& after, const auto&, const auto&) {
      sv::Segmentation whole;
      cv::Mat diff, channels[3];
      cv::absdiff(empty_table, after, diff);
      cv::split(diff, channels);
      whole.mask = cv::max(cv::max(channels[0], channels[1]), channels[2]) > 20;
      return whole;
    });
    const Eigen::Vector3d rest = nudge_and_park(s, object);
    s.on_right_still(draw_scene(scene_, {1280, 960}, {rest}), now_, now_);
    const auto ended = outputs_of<sv::AttemptEnded>(s.take_outputs());
    ASSERT_EQ(ended.at(0).attempt->outcome, sv::Outcome::Segmented);
    const Eigen::Vector3d ray = along_ray(rest), across(-ray.y(), ray.x(), 0.0);
    // 6 cm farther along the ray and 2 cm to one side (or 9 cm to the other, where its push stays
    // clear of the object at rest): on neither camera's line of the object's axis (more than the
    // 6 px agreement off), but 2 cm is inside its image.
    const Eigen::Vector3d mate = rest + 0.06 * ray + (on_the_object ? 0.02 : -0.09) * across;
    for (const bool left : {true, false}) {
      const auto of_rest = left ? scene_.left_axis_line(rest, 0.25, {640, 480}) : scene_.right_axis_line(rest, 0.25, {640, 480});
      const auto of_mate = left ? scene_.left_axis_line(mate, 0.25, {640, 480}) : scene_.right_axis_line(mate, 0.25, {640, 480});
      ASSERT_TRUE(of_rest && of_mate);
      EXPECT_FALSE(sv::lines_agree(*of_mate, *of_rest, 3 * M_PI / 180, 6)) << (left ? "left" : "right");
    }
    answer_survey(s, {mate});
    if (on_the_object) {
      EXPECT_EQ(s.state(), sv::State::Done) << s.report().reason;
      ASSERT_EQ(s.summary().rejections.size(), 1u);
      EXPECT_EQ(s.summary().rejections.begin()->first, "already explored");
    } else {
      EXPECT_EQ(s.state(), sv::State::SnapshotBefore) << s.report().reason;
    }
  }
}

// The arm's base column is symmetric: a stereo mismatch of its line gives a candidate behind it
// (on its line in one camera), where that camera cannot see anything. Not nudged; the object is.
TEST_F(SupervisorTest, ACandidateHiddenBehindTheArmsBaseIsPassedOverWithItsReason) {
  sv::Supervisor s = make();
  Eigen::Vector3d away = -scene_.right_camera_in_world();  // from the right camera through the base
  away.z() = 0;
  const Eigen::Vector3d behind = 0.18 * away.normalized();
  const Eigen::Vector3d object(0.28, -0.05, 0);
  start_with(s, {behind, object});
  ASSERT_EQ(s.state(), sv::State::SnapshotBefore) << s.report().reason;
  EXPECT_NEAR((s.report().target - object).norm(), 0.0, 1e-9);
  sv::Supervisor alone = make();
  start_with(alone, {behind});
  EXPECT_EQ(alone.state(), sv::State::Done);
  EXPECT_NE(alone.summary().end_reason.find("behind the arm's base"), std::string::npos) << alone.summary().end_reason;
}

// A survey that paired the object's right line with another left line: a candidate `behind_m`
// beyond the object at (0.22, -0.05) on its right-camera line (negative: before it), seen in 9 of
// 10 frames, and the object's own, seen in 4 (not "seen": the other is chosen first); and, when
// given, a `third` candidate both cameras see in every frame. The nudge commanded, if any.
std::optional<sv::NudgeCommand> SupervisorTest::nudge_of_rivals_on_one_right_line(const sv::Config& config, double behind_m,
                                                                                  const std::optional<Eigen::Vector3d>& third) {
  // The survey's choice must be the mismatch. Every push of it 10 cm before the object passes by
  // the object, a doubtful candidate (4 of 10 frames), so by default the mismatch would wait and
  // the object be chosen outright (TargetParams::defer_for_doubtful): not the rule tested here.
  sv::Config without_waiting = config;
  without_waiting.targets.defer_for_doubtful = false;
  sv::Supervisor s = make(without_waiting);
  const Eigen::Vector3d object(0.22, -0.05, 0);
  const Eigen::Vector3d mismatch = object + behind_m * along_ray(object);
  s.start(now_, 100);
  s.on_services({}, now_);
  const auto right = scene_.right_axis_line(object, 0.25, {640, 480});
  const auto left_object = scene_.left_axis_line(object, 0.25, {640, 480});
  const auto left_mismatch = scene_.left_axis_line(mismatch, 0.25, {640, 480});
  EXPECT_TRUE(right && left_object && left_mismatch);
  EXPECT_TRUE(sv::lines_agree(*scene_.right_axis_line(mismatch, 0.25, {640, 480}), *right, 0.01, 1));
  for (int i = 0; i < 10; ++i) {
    std::vector<nudge::symmetry::Line> left, rights{*right};
    if (i < 9) left.push_back(*left_mismatch);
    if (i < 4) left.push_back(*left_object);
    if (third) {
      left.push_back(*scene_.left_axis_line(*third, 0.25, {640, 480}));
      rights.push_back(*scene_.right_axis_line(*third, 0.25, {640, 480}));
    }
    s.on_lines(true, left, now_ + kSecond / 10, now_ + kSecond / 5);
    s.on_lines(false, rights, now_ + kSecond / 10, now_ + kSecond / 5);
  }
  now_ += kSecond;
  s.take_outputs();
  std::vector<sv::Candidate> candidates{{0, mismatch, 20}, {1, object, 20}};
  if (third) candidates.push_back({2, *third, 20});
  s.on_candidates(candidates, now_, now_);
  EXPECT_EQ(s.state(), sv::State::SnapshotBefore) << s.report().reason;
  EXPECT_NEAR((s.report().target - mismatch).norm(), 0.0, 1e-9) << "the mismatch is chosen first";
  std::vector<Eigen::Vector3d> drawn{object};
  if (third) drawn.push_back(*third);
  s.on_right_still(draw_scene(scene_, {1280, 960}, drawn), now_, now_);
  const auto nudges = outputs_of<sv::NudgeCommand>(s.take_outputs());
  if (nudges.size() != 1u) {
    ADD_FAILURE() << "no nudge: " << s.report().reason;
    return std::nullopt;
  }
  return nudges[0];
}

TEST_F(SupervisorTest, ACandidateBeyondTheFootOfItsLineGivesWayToTheOneOnThatLineTheFootShows) {
  const Eigen::Vector3d object(0.22, -0.05, 0);  // its drawn line's foot: about 2 cm behind its axis
  // 10 cm before the object (a mismatch) stands 15 cm from the typical 3 cm beyond the foot, the
  // object 5 cm: the object's own candidate is nudged instead.
  EXPECT_NEAR((nudged_of_rivals_on_one_right_line({}, -0.10) - object).norm(), 0.0, 1e-9);
  sv::Config off = drawn_config();
  off.rival_by_foot = false;
  EXPECT_NEAR((nudged_of_rivals_on_one_right_line(off, -0.10) - object).norm(), 0.10, 1e-9);
  // 5 cm behind fits the foot better than the object does: the survey's choice stands.
  EXPECT_NEAR((nudged_of_rivals_on_one_right_line({}, 0.05) - object).norm(), 0.05, 1e-9);
}

// The push of the candidate nudged in place of the survey's choice keeps clear of the survey's
// other candidates, as every push does: a third candidate 15 cm to one side across the view sits
// where the pad would come down if the object were pushed away from it, and beyond where the
// object slides if pushed towards it. Whichever side it stands on, the push goes towards it.
TEST_F(SupervisorTest, TheCandidateNudgedInsteadIsPushedClearOfTheOtherCandidates) {
  const Eigen::Vector3d object(0.22, -0.05, 0);
  const Eigen::Vector3d ray = along_ray(object);
  const Eigen::Vector3d across(-ray.y(), ray.x(), 0);
  for (const double side : {1.0, -1.0}) {
    const Eigen::Vector3d third = object + side * 0.15 * across;
    const auto nudge = nudge_of_rivals_on_one_right_line({}, -0.10, third);
    ASSERT_TRUE(nudge) << "side " << side;
    EXPECT_NEAR((nudge->target - object).norm(), 0.0, 1e-9) << "side " << side;
    EXPECT_GT(nudge->direction.dot(third - object), 0.0) << "side " << side << ": the pad came down by the third";
  }
}

// A survey whose only candidate is the object at (0.22, -0.05); the right camera's lines also show
// a second object `beside` in every frame, which no left line pairs (so no candidate). The nudge
// commanded, if any, and the supervisor's last reason.
std::pair<std::optional<sv::NudgeCommand>, std::string> SupervisorTest::nudge_beside_an_unpaired_object(
    const sv::Config& config, const Eigen::Vector3d& beside) {
  sv::Supervisor s = make(config);
  const Eigen::Vector3d object(0.22, -0.05, 0);
  s.start(now_, 100);
  s.on_services({}, now_);
  // The unpaired object's line: its support's lower end over the front of its base.
  const auto right_beside = scene_.right_axis_line(beside - 0.03 * along_ray(beside), 0.25, {640, 480});
  const auto right = scene_.right_axis_line(object, 0.25, {640, 480});
  const auto left = scene_.left_axis_line(object, 0.25, {640, 480});
  EXPECT_TRUE(right && left && right_beside);
  for (int i = 0; i < 10; ++i) {
    s.on_lines(true, {*left}, now_ + kSecond / 10, now_ + kSecond / 5);
    s.on_lines(false, {*right, *right_beside}, now_ + kSecond / 10, now_ + kSecond / 5);
  }
  now_ += kSecond;
  s.take_outputs();
  s.on_candidates({{0, object, 20}}, now_, now_);
  if (s.state() != sv::State::SnapshotBefore) return {std::nullopt, s.report().reason};
  s.on_right_still(draw_scene(scene_, {1280, 960}, {object}), now_, now_);
  const auto nudges = outputs_of<sv::NudgeCommand>(s.take_outputs());
  if (nudges.empty()) return {std::nullopt, s.report().reason};
  return {nudges[0], s.report().reason};
}

TEST_F(SupervisorTest, AnObjectOnlyOneCameraSawIsKeptOffThePushWithLineObstaclesOn) {
  const Eigen::Vector3d object(0.22, -0.05, 0);
  sv::Config on = drawn_config();
  on.line_obstacle_share = 0.5;
  // Where the push goes with nothing else on the table.
  const auto [free, free_reason] = nudge_beside_an_unpaired_object(on, Eigen::Vector3d(0.22, 0.30, 0));
  ASSERT_TRUE(free) << free_reason;
  const Eigen::Vector3d direction = free->direction.normalized();
  // An object 9 cm before the target against that direction: on the pad's way in.
  const Eigen::Vector3d in_the_way = object - 0.09 * direction;
  const auto [off_nudge, off_reason] = nudge_beside_an_unpaired_object({}, in_the_way);
  ASSERT_TRUE(off_nudge) << off_reason;
  EXPECT_GT(off_nudge->direction.normalized().dot(direction), 0.99) << "off: the lines' object is unknown to the planner";
  const auto [on_nudge, on_reason] = nudge_beside_an_unpaired_object(on, in_the_way);
  if (on_nudge) {
    EXPECT_LT(on_nudge->direction.normalized().dot(direction), 0.9) << "pushed through the object one camera saw";
  } else {
    EXPECT_NE(on_reason.find("object seen in one camera"), std::string::npos) << on_reason;
  }
}

// ---- learning by interaction (thesis ch. 7): recognise, grasp, turn, learn, put back ----

TEST(Grasp, TheObjectTopIsTheLargestBlobsFirstPixelOnTheLine) {
  cv::Mat mask = cv::Mat::zeros(200, 300, CV_8U);
  cv::rectangle(mask, cv::Rect(120, 60, 60, 120), cv::Scalar(255), cv::FILLED);  // the object
  cv::rectangle(mask, cv::Rect(140, 5, 20, 20), cv::Scalar(255), cv::FILLED);    // motion above it, smaller
  nudge::symmetry::Line vertical;  // x = 150: R = 150 - 149.5, theta = 0
  vertical.r = 0.5;
  vertical.theta = 0;
  const auto top = sv::object_top(mask, vertical);
  ASSERT_TRUE(top);
  EXPECT_NEAR(top->x, 150, 1e-9);
  EXPECT_EQ(top->y, 60);  // not 5: the smaller blob is not the object
  nudge::symmetry::Line beside = vertical;
  beside.r = 100;  // x = 249.5 misses the object
  EXPECT_FALSE(sv::object_top(mask, beside));
  EXPECT_FALSE(sv::object_top(cv::Mat::zeros(200, 300, CV_8U), vertical));
}

// Where the grasp tests stand an upright object: ahead of the base, to its right and to its left.
const std::vector<Eigen::Vector3d> kUprightObjectPlaces = {Eigen::Vector3d(0.25, 0.0, 0), Eigen::Vector3d(0.30, -0.08, 0),
                                                           Eigen::Vector3d(0.22, 0.10, 0)};

// One camera and the table find where a cylinder stands: its base's front on the line, pushed back
// by the radius its mask's width gives; wherever a stereo mismatch would put it along the ray.
TEST(Grasp, TheMasksFootIsWhereTheUprightObjectStands) {
  const sv::SceneGeometry scene = make_scene();
  const cv::Size still(1280, 960);
  for (const Eigen::Vector3d& foot : kUprightObjectPlaces)
    for (double radius : {0.03, 0.045}) {
      const cv::Mat mask = cylinder_mask(scene, still, foot, radius, 0.12);
      const auto line = scene.right_axis_line(foot, 0.12, still);
      ASSERT_TRUE(line);
      const auto found = sv::foot_from_mask(scene, mask, *line);
      ASSERT_TRUE(found) << foot.transpose();
      EXPECT_LT((*found - foot).norm(), 0.004) << "at " << foot.transpose() << ", radius " << radius;
    }
  const Eigen::Vector3d foot(0.25, 0.0, 0);
  nudge::symmetry::Line beside = *scene.right_axis_line(foot + Eigen::Vector3d(0, 0.2, 0), 0.12, still);
  EXPECT_FALSE(sv::foot_from_mask(scene, cylinder_mask(scene, still, foot, 0.03, 0.12), beside)) << "the line misses the blob";
  EXPECT_FALSE(sv::foot_from_mask(scene, cv::Mat::zeros(still, CV_8U), *scene.right_axis_line(foot, 0.12, still)));
}

// A mug's handle sticks out on one side of the line: the base's width is read on the narrower
// side, so the handle does not push the foot back along the ray.
TEST(Grasp, AHandleOnOneSideDoesNotMoveTheMasksFoot) {
  const sv::SceneGeometry scene = make_scene();
  const cv::Size still(1280, 960);
  for (const Eigen::Vector3d& foot : {Eigen::Vector3d(0.25, 0.0, 0), Eigen::Vector3d(0.30, -0.08, 0)}) {
    cv::Mat mask = cylinder_mask(scene, still, foot, 0.04, 0.10);
    // The handle: a smaller upright cylinder joined to the mug's body, 2-9 cm above the table
    // (the simulated mug's: 1.8-8.3 cm, 7 cm out from the axis), turned half way towards the
    // camera: nearer, it reaches down among the base's rows in the image.
    Eigen::Vector3d towards = scene.right_camera_in_world() - foot;
    towards.z() = 0;
    towards.normalize();
    const Eigen::Vector3d across(-towards.y(), towards.x(), 0);
    const Eigen::Vector3d beside = 0.055 * (towards + across).normalized();
    cv::Mat handle = cylinder_mask(scene, still, foot + beside + Eigen::Vector3d(0, 0, 0.02), 0.016, 0.07);
    mask |= handle;
    const auto line = scene.right_axis_line(foot, 0.10, still);
    ASSERT_TRUE(line);
    const auto found = sv::foot_from_mask(scene, mask, *line);
    ASSERT_TRUE(found) << foot.transpose();
    EXPECT_LT((*found - foot).norm(), 0.004) << "at " << foot.transpose();
  }
}

// A segmentation that kept only a sliver of the object's lower part (the demo's white bottle) has
// no foot to give: its base's width would put the foot short along the ray.
TEST(Grasp, AMaskWithoutTheObjectsLowerPartGivesNoFoot) {
  const sv::SceneGeometry scene = make_scene();
  const cv::Size still(1280, 960);
  const Eigen::Vector3d foot(0.25, 0.0, 0);
  cv::Mat mask = cylinder_mask(scene, still, foot, 0.035, 0.20);
  const auto line = scene.right_axis_line(foot, 0.20, still);
  ASSERT_TRUE(line);
  ASSERT_TRUE(sv::foot_from_mask(scene, mask, *line)) << "the whole object";
  // The lowest quarter cut to a strip a fifth of the object's width, on the line.
  std::vector<cv::Point> on;
  cv::findNonZero(mask, on);
  const cv::Rect box = cv::boundingRect(on);
  const int cut = box.y + 3 * box.height / 4;
  const int middle = static_cast<int>(std::lround((mask.cols - 1) / 2.0 + line->r / std::cos(line->theta) -
                                                  (cut - (mask.rows - 1) / 2.0) * std::tan(line->theta)));
  cv::Mat lower = mask.rowRange(cut, mask.rows);
  cv::Mat strip = cv::Mat::zeros(lower.size(), CV_8U);
  strip.colRange(middle - box.width / 10, middle + box.width / 10).setTo(255);
  lower &= strip;
  EXPECT_FALSE(sv::foot_from_mask(scene, mask, *line));
}

// A known object standing in front hides the target's base: the mask ends at its outline, and the
// foot read there lies far along the ray. The front is then known to be hidden.
TEST(Grasp, AMasksFrontHiddenByANearerKnownObjectIsNoBase) {
  const sv::SceneGeometry scene = make_scene();
  const cv::Size still(1280, 960);
  const Eigen::Vector3d foot(0.22, -0.10, 0);
  Eigen::Vector3d towards = scene.right_camera_in_world() - foot;
  towards.z() = 0;
  towards.normalize();
  const Eigen::Vector3d across(-towards.y(), towards.x(), 0);
  const Eigen::Vector3d in_front = foot + 0.10 * towards + 0.02 * across, behind = foot - 0.12 * towards;
  const auto line = scene.right_axis_line(foot, 0.20, still);
  ASSERT_TRUE(line);
  const cv::Mat whole = cylinder_mask(scene, still, foot, 0.035, 0.20);
  const cv::Mat hidden = whole & ~cylinder_mask(scene, still, in_front, 0.04, 0.10);
  const auto reading = sv::read_mask_on_line(hidden, *line);
  ASSERT_TRUE(reading);
  const auto short_foot = sv::foot_from_mask(scene, *reading);
  ASSERT_TRUE(short_foot);
  EXPECT_GT((*short_foot - foot).norm(), 0.03) << "the foot read at the nearer object's outline";
  // The object stands at `foot` by another measure (the settled axes).
  EXPECT_TRUE(sv::mask_front_hidden_by(scene, *reading, foot, in_front, 0.045, 0.10));
  // Standing behind the object, or far beside its line, it hides nothing of it.
  EXPECT_FALSE(sv::mask_front_hidden_by(scene, *reading, foot, behind, 0.045, 0.10));
  EXPECT_FALSE(sv::mask_front_hidden_by(scene, *reading, foot, in_front + 0.15 * across, 0.045, 0.10));
  // The whole object's front is its base: a low object farther in front is below it in the image.
  const auto whole_reading = sv::read_mask_on_line(whole, *line);
  ASSERT_TRUE(whole_reading);
  const auto true_foot = sv::foot_from_mask(scene, *whole_reading);
  ASSERT_TRUE(true_foot);
  EXPECT_LT((*true_foot - foot).norm(), 0.004);
  EXPECT_FALSE(sv::mask_front_hidden_by(scene, *whole_reading, foot, foot + 0.16 * towards, 0.045, 0.02));
  EXPECT_TRUE(sv::mask_front_hidden_by(scene, *whole_reading, foot, foot + 0.16 * towards, 0.045, 0.10)) << "taller, it would hide the base";
}

// The object's width where the fingers close, read from its right segmentation.
TEST(Grasp, TheObjectsWidthAtTheGraspHeightComesFromItsMask) {
  const sv::SceneGeometry scene = make_scene();
  const cv::Size still(1280, 960);
  for (const Eigen::Vector3d& foot : kUprightObjectPlaces)
    for (double radius : {0.03, 0.045}) {
      const cv::Mat mask = cylinder_mask(scene, still, foot, radius, 0.15);
      const auto width = sv::object_width_at(scene, mask, foot, 0.07);
      ASSERT_TRUE(width) << foot.transpose();
      EXPECT_NEAR(*width, 2 * radius, 0.1 * radius) << "at " << foot.transpose() << ", radius " << radius;
    }
  const Eigen::Vector3d foot(0.25, 0.0, 0);
  EXPECT_FALSE(sv::object_width_at(scene, cylinder_mask(scene, still, foot, 0.03, 0.05), foot, 0.12)) << "above its top";
  EXPECT_FALSE(sv::object_width_at(scene, cv::Mat::zeros(still, CV_8U), foot, 0.05)) << "no mask";
}

// The fingers close 65 mm below the estimated top (both rows of faces below a bottle's shoulder,
// where its sides are vertical, and over as little of its label as that allows), and no lower
// than half way up a short object.
TEST(Grasp, TheFingersCloseBelowTheTopOnTheSidesNotOnTheCap) {
  const sv::GraspTargetParams params;
  EXPECT_NEAR(sv::grip_height(0.20, params), 0.135, 1e-12);  // a 200 mm bottle: below its shoulder
  EXPECT_NEAR(sv::grip_height(0.35, params), 0.285, 1e-12);
  EXPECT_NEAR(sv::grip_height(0.12, params), 0.06, 1e-12);   // a can: half way up, not 55 mm
  EXPECT_NEAR(sv::grip_height(0.13, params), 0.065, 1e-12);  // where the two rules meet
  sv::GraspTargetParams shallow = params;
  shallow.grip_depth_m = 0.01;
  EXPECT_NEAR(sv::grip_height(0.20, shallow), 0.19, 1e-12);
  // Through grasp_target: a 250 mm top, seen by both cameras, is gripped 65 mm below its
  // estimated (lowered) top.
  const sv::SceneGeometry scene = make_scene();
  const Eigen::Vector3d foot(0.28, -0.05, 0), top(0.28, -0.05, 0.25);
  const cv::Size still(1280, 960);
  const sv::GraspTarget g = sv::grasp_target(scene, *scene.project_left(top, still), *scene.project_right(top, still), still, foot);
  ASSERT_TRUE(g.ok()) << g.reason;
  EXPECT_NEAR(g.top_height_m, 0.25 - g.overestimate_m, 1e-6);
  EXPECT_NEAR(g.grasp_height_m, g.top_height_m - params.grip_depth_m, 1e-6);
  EXPECT_NEAR(params.grip_depth_m, 0.065, 1e-12);
  EXPECT_LT(g.grasp_height_m, g.top_height_m);
}

TEST(Grasp, TheTriangulatedTopIsLoweredByRTanTheta) {
  const sv::SceneGeometry scene = make_scene();
  const Eigen::Vector3d foot(0.28, -0.05, 0), top(0.28, -0.05, 0.12);
  const cv::Size still(1280, 960);
  const auto left = scene.project_left(top, still), right = scene.project_right(top, still);
  const sv::GraspTarget g = sv::grasp_target(scene, *left, *right, still, foot);
  ASSERT_TRUE(g.ok()) << g.reason;
  EXPECT_LT((g.top - top).norm(), 1e-6);
  const Eigen::Vector3d camera = scene.right_camera_in_world();
  const double theta = std::atan2(camera.z() - top.z(), (camera - top).head<2>().norm());
  EXPECT_NEAR(g.overestimate_m, 0.06 * std::tan(theta), 1e-9);
  EXPECT_NEAR(g.top_height_m, 0.12 - g.overestimate_m, 1e-6);
  EXPECT_NEAR(g.grasp_height_m, sv::grip_height(g.top_height_m, {}), 1e-12);
  // A top that is the table itself cannot be grasped; the reason says so.
  const sv::GraspTarget flat = sv::grasp_target(scene, *scene.project_left(foot, still), *scene.project_right(foot, still), still, foot);
  EXPECT_FALSE(flat.ok());
  EXPECT_NE(flat.reason.find("too low"), std::string::npos) << flat.reason;
  // The box of a cylinder contains its axis' projection.
  const cv::Rect box = sv::cylinder_box(scene, foot, 0.04, 0, 0.12, still);
  EXPECT_TRUE(box.contains(cv::Point(*right)) || box.contains(cv::Point(right->x, right->y + 1)));
  EXPECT_TRUE(box.contains(cv::Point(*scene.project_right(foot, still))));
}

namespace {

sv::ArmStatus gripping(sv::ArmStatus::Motion motion, int64_t seq, double opening) {
  sv::ArmStatus a = arm(motion, seq);
  a.gripper_opening = opening;
  return a;
}

class LearningTest : public SupervisorTest {
 protected:
  const Eigen::Vector3d object_{0.28, -0.05, 0};
  Eigen::Vector3d rest_;

  sv::Supervisor make_learning(sv::Config config = drawn_config()) {
    config.learn = sv::Config::Learn::On;
    return sv::Supervisor(config, scene_, sv::ArmSetup{}, mask_of_the_moved_object);
  }
  // The after still's drawn object (coloured, on the grey table; these tests' scenes hold the one
  // object): where it came to rest, as the motion segmentation refines it (fig. 6.7), and as wide
  // as it is where the fingers close.
  static sv::Segmentation mask_of_the_moved_object(const cv::Mat&, const cv::Mat& after, const nudge::symmetry::Line&,
                                                   const nudge::symmetry::Line&) {
    sv::Segmentation s;
    std::vector<cv::Mat> channels;
    cv::split(after, channels);
    cv::Mat low, high;
    cv::min(channels[0], channels[1], low);
    cv::min(low, channels[2], low);
    cv::max(channels[0], channels[1], high);
    cv::max(high, channels[2], high);
    s.mask = (high - low) > 30;  // the table is grey, the object's outer bands coloured
    return s;
  }
  void stills(sv::Supervisor& s, const std::vector<Eigen::Vector3d>& objects) {
    now_ += kSecond / 5;
    s.on_right_still(draw_scene(scene_, {1280, 960}, objects), now_, now_);
    s.on_left_still(draw_scene(scene_, {1280, 960}, objects, true), now_, now_);
  }
  // Up to the recognition request (both stills asked for and given).
  sv::RecognizeRequest to_recognition(sv::Supervisor& s) {
    const auto out = start_with(s, {object_});
    const auto asked = outputs_of<sv::SnapshotRequest>(out);
    EXPECT_TRUE(asked.size() == 1 && asked[0].both);
    stills(s, {object_});
    EXPECT_EQ(s.state(), sv::State::Recognise) << s.report().reason;
    return outputs_of<sv::RecognizeRequest>(s.take_outputs()).at(0);
  }
  // Not recognised: nudged, settled, parked, both after stills: the grasp command.
  sv::GraspCommand to_grasp(sv::Supervisor& s) {
    const sv::RecognizeRequest request = to_recognition(s);
    s.on_recognition(request.seq, "", "no object matched 3 or more features", now_);
    const auto nudge = outputs_of<sv::NudgeCommand>(s.take_outputs()).at(0);
    rest_ = object_ + 0.03 * nudge.direction;
    play_nudge(s, nudge.seq, object_, rest_);
    settle_with_axes(s, {rest_});
    park(s);
    EXPECT_EQ(s.state(), sv::State::SnapshotAfter) << s.report().reason;
    s.take_outputs();
    stills(s, {rest_});
    EXPECT_EQ(s.state(), sv::State::Grasp) << s.report().reason;
    return outputs_of<sv::GraspCommand>(s.take_outputs()).at(0);
  }
  // The arm reports the command done, holding (opening 6 cm).
  void done(sv::Supervisor& s, int64_t seq, double opening = 0.06) {
    s.on_arm_state(gripping(sv::ArmStatus::Motion::Moving, seq, opening), now_ += kSecond / 2);
    s.on_arm_state(gripping(sv::ArmStatus::Motion::Done, seq, opening), now_ += kSecond / 2);
  }
  std::shared_ptr<const sv::Attempt> ended(const std::vector<sv::Output>& out) {
    const auto e = outputs_of<sv::AttemptEnded>(out);
    EXPECT_EQ(e.size(), 1u);
    return e.empty() ? nullptr : e[0].attempt;
  }
};

}  // namespace

TEST_F(LearningTest, GraspsTurnsTwelveTimesLearnsAndPutsTheObjectBack) {
  sv::Config config = drawn_config();
  config.standing_view = true;  // off by default (Config::standing_view); the test without it follows
  sv::Supervisor s = make_learning(config);
  const sv::GraspCommand grasp = to_grasp(s);
  EXPECT_EQ(s.awaited_arm_seq(), grasp.seq);
  // Above the axis' foot where the object came to rest, the fingers half way up this short object
  // (12 cm box, its top lowered by r tan(theta) ~ 3 cm: grip_height).
  EXPECT_LT((grasp.position - rest_).head<2>().norm(), 0.006);
  EXPECT_GT(grasp.height, 0.03);
  EXPECT_LT(grasp.height, 0.06);
  done(s, grasp.seq);
  std::vector<sv::LearnView> views;
  sv::LearnView scene_still;
  std::vector<sv::LearnCommit> commits;
  for (int view = 0; view < 12; ++view) {
    ASSERT_EQ(s.state(), sv::State::Rotate) << s.report().reason;
    auto out = s.take_outputs();
    ASSERT_EQ(outputs_of<sv::SnapshotRequest>(out).size(), 1u);
    EXPECT_FALSE(outputs_of<sv::SnapshotRequest>(out)[0].both);
    now_ += kSecond / 5;
    s.on_right_still(draw_scene(scene_, {1280, 960}, {}), now_, now_);
    out = s.take_outputs();
    const auto taken = outputs_of<sv::LearnView>(out);
    // With the last view, before the commit: the standing view (the after still, Config::
    // standing_view) and the before still as the scene (the object stood elsewhere in it).
    ASSERT_EQ(taken.size(), view < 11 ? 1u : 3u);
    views.push_back(taken[0]);
    if (view == 11) views.push_back(taken[1]), scene_still = taken[2];
    commits = outputs_of<sv::LearnCommit>(out);
    if (view < 11) {
      ASSERT_EQ(outputs_of<sv::RotateCommand>(out).size(), 1u) << view << ": " << s.report().reason;
      const auto turn = outputs_of<sv::RotateCommand>(out).at(0);
      EXPECT_NEAR(std::abs(turn.angle), M_PI / 6, 1e-12);
      done(s, turn.seq);
    }
  }
  ASSERT_EQ(s.state(), sv::State::Learn);
  for (int i = 0; i < 12; ++i) {
    EXPECT_EQ(views[i].index, i);
    EXPECT_NEAR(std::abs(views[i].angle), i * M_PI / 6, 1e-9);
    EXPECT_EQ(views[i].object_key, "attempt_01");
    EXPECT_GT(views[i].box.area(), 0);
    EXPECT_FALSE(views[i].scene);
  }
  const sv::LearnView& standing = views[12];
  EXPECT_EQ(standing.index, 12);
  EXPECT_FALSE(standing.scene);
  EXPECT_TRUE(scene_still.scene);
  EXPECT_EQ(scene_still.object_key, "attempt_01");
  ASSERT_EQ(commits.size(), 1u);
  const sv::LearnCommit commit = commits[0];
  EXPECT_EQ(commit.views, 13);
  EXPECT_GT(commit.height, 0.06);
  EXPECT_EQ(commit.object_key, "attempt_01");
  s.on_learned(commit.seq + 1, true, "other", "", now_);  // not ours
  EXPECT_EQ(s.state(), sv::State::Learn);
  s.on_learned(commit.seq, true, "object_1", "", now_ += kSecond);
  ASSERT_EQ(s.state(), sv::State::Place);
  const auto place = outputs_of<sv::PlaceCommand>(s.take_outputs()).at(0);
  EXPECT_LT((place.position - object_).norm(), 1e-9) << "back where it stood before the nudge";
  EXPECT_NEAR(place.height, grasp.height, 1e-12);
  done(s, place.seq);
  auto out = s.take_outputs();
  const auto a = ended(out);
  ASSERT_TRUE(a);
  EXPECT_EQ(a->outcome, sv::Outcome::Segmented);
  EXPECT_EQ(a->learning, "learned");
  EXPECT_EQ(a->learned_name, "object_1");
  EXPECT_EQ(a->views.size(), 13u);
  ASSERT_EQ(scene_still.image.size(), a->before.size());
  EXPECT_EQ(cv::norm(scene_still.image, a->before, cv::NORM_INF), 0.0) << "the scene still is the before still";
  ASSERT_EQ(standing.image.size(), a->after.size());
  EXPECT_EQ(cv::norm(standing.image, a->after, cv::NORM_INF), 0.0) << "the standing view is the after still";
  EXPECT_EQ(standing.box, cv::boundingRect(a->segmentation.mask)) << "boxed by the right segmentation";
  ASSERT_EQ(standing.mask.size(), a->segmentation.mask.size()) << "and sent with it, so that its outline is not learned";
  EXPECT_EQ(cv::norm(standing.mask, a->segmentation.mask, cv::NORM_INF), 0.0);
  for (int i = 0; i < 12; ++i) EXPECT_TRUE(views[i].mask.empty()) << "the turned views have their box alone";
  EXPECT_EQ(standing.utime, a->after_utime);
  ASSERT_TRUE(a->top[0] && a->top[1] && a->grasp);
  EXPECT_GE(a->grasp_plan_ms, 0.0) << "the grasp's plan time is recorded for the report";
  EXPECT_GT(a->grasp_plan_cpu_ms, 0.0) << "and its CPU time on the supervisor's thread";
  EXPECT_LE(a->grasp_plan_cpu_ms, a->grasp_plan_ms + 1.0) << "one thread's CPU time within the wall time (clock resolution)";
  // Where the plan's time went, by stage: the supervisor thread's, then the left camera's.
  std::vector<std::string> stage_names;
  double supervisor_thread_ms = 0;
  for (const auto& [stage, ms] : a->grasp_plan_stages_ms) {
    stage_names.push_back(stage);
    EXPECT_GE(ms, 0.0) << stage;
    if (stage.rfind("left", 0) != 0 && stage.rfind("wait", 0) != 0) supervisor_thread_ms += ms;
  }
  EXPECT_EQ(stage_names, (std::vector<std::string>{"right rest from the still", "right before line", "right after line",
                                                   "right segmentation", "right mask's neighbours cleared",
                                                   "wait for the left camera (wall)", "right mask checks",
                                                   "grasp and arm plan", "left lines", "left segmentation"}));
  EXPECT_LE(supervisor_thread_ms, a->grasp_plan_cpu_ms + 1e-6) << "the thread's stages within its CPU time";
  EXPECT_EQ(outputs_of<sv::HomeCommand>(out).size(), 1u) << "the arm parks after putting it back";
  EXPECT_EQ(s.summary().learned, 1);
  ASSERT_TRUE(a->put_back_at);
  EXPECT_LT((*a->put_back_at - object_).norm(), 1e-9);
  // The next survey is told the object stands where it was put back, not at its rest.
  park(s);
  const auto survey = outputs_of<sv::CandidatesRequest>(s.take_outputs());
  ASSERT_EQ(survey.size(), 1u);
  ASSERT_EQ(survey[0].explored.size(), 1u);
  EXPECT_LT((survey[0].explored[0] - object_).head<2>().norm(), 1e-9) << "not at the rest " << rest_.transpose();
}

// A candidate 5 cm behind the object along the ray (a stable stereo mismatch), and the settled
// axes as far behind its rest: the grasp goes where the after still's mask stands, and the object
// goes back where it stood, not where the candidate was. With the candidate right and only the
// settled axes off (the demo's mug), it goes back to the candidate.
// With learning, the left camera's segmentation runs beside the right after line's search, about
// the settled axes' rest. When a weak after line gives way to a stronger one along the push (a
// small neighbour's axes the only settled group, as in the test of the rule above), the left
// segmentation is run again about the new rest: the grasp is planned on the object, its fingers
// half way up it, not on the neighbour's top.
TEST_F(LearningTest, WithoutTheStandingViewTwelveViewsArePrunedAgainstTheAfterStill) {
  sv::Config config = drawn_config();
  config.standing_view = false;
  sv::Supervisor s = make_learning(config);
  done(s, to_grasp(s).seq);
  std::vector<sv::LearnView> sent;
  for (int view = 0; view < 12; ++view) {
    ASSERT_EQ(s.state(), sv::State::Rotate) << s.report().reason;
    s.take_outputs();
    now_ += kSecond / 5;
    s.on_right_still(draw_scene(scene_, {1280, 960}, {}), now_, now_);
    auto out = s.take_outputs();
    for (const auto& v : outputs_of<sv::LearnView>(out)) sent.push_back(v);
    if (view < 11) {
      done(s, outputs_of<sv::RotateCommand>(out).at(0).seq);
      continue;
    }
    const sv::LearnCommit commit = outputs_of<sv::LearnCommit>(out).at(0);
    EXPECT_EQ(commit.views, 12);
    s.on_learned(commit.seq, true, "object_1", "", now_ += kSecond);
  }
  done(s, outputs_of<sv::PlaceCommand>(s.take_outputs()).at(0).seq);
  auto out = s.take_outputs();
  const auto a = ended(out);
  ASSERT_TRUE(a);
  EXPECT_EQ(a->views.size(), 12u);
  ASSERT_EQ(sent.size(), 13u);  // twelve views, then the scene still
  EXPECT_TRUE(sent.back().scene);
  EXPECT_EQ(cv::norm(sent.back().image, a->after, cv::NORM_INF), 0.0) << "the scene still is the after still";
}

TEST_F(LearningTest, AWeakAfterLineMovesTheLeftCamerasSegmentationWithTheRest) {
  const Shape small{0.025, 0.022, /*grey=*/true};  // outside these tests' masks of coloured pixels
  sv::Config config = drawn_config();
  config.rest_mask_disagreement_m = 0;  // the rest as the stills' lines place it (see the rule's test)
  // The drawn object's bands are thin beside its width: a line a few px off its drawn middle
  // mirrors them onto each other's gaps (the mirror check is not what this test is about).
  config.min_mask_mirror_agreement = 0;
  auto both_stills = [&](sv::Supervisor& s, const std::vector<Eigen::Vector3d>& objects) {
    now_ += kSecond / 5;
    s.on_right_still(draw_scene(scene_, {1280, 960}, objects, false, {small, Shape{}}), now_, now_);
    s.on_left_still(draw_scene(scene_, {1280, 960}, objects, true, {small, Shape{}}), now_, now_);
  };
  sv::Supervisor probe = make_learning(config);
  const sv::RecognizeRequest probed = to_recognition(probe);
  probe.on_recognition(probed.seq, "", "no object matched 3 or more features", now_);
  const Eigen::Vector3d direction = outputs_of<sv::NudgeCommand>(probe.take_outputs()).at(0).direction;
  const Eigen::Vector3d neighbour = object_ - 0.025 * direction + 0.06 * along_ray(object_);

  sv::Supervisor s = make_learning(config);
  std::vector<nudge::symmetry::Line> left_after_lines;  // each left segmentation's after line, in order
  s.set_left_segmentation([&](const cv::Mat& before, const cv::Mat& after, const nudge::symmetry::Line& before_line,
                              const nudge::symmetry::Line& after_line) {
    left_after_lines.push_back(after_line);
    return mask_of_the_moved_object(before, after, before_line, after_line);
  });
  start_with(s, {object_});
  both_stills(s, {neighbour, object_});
  ASSERT_EQ(s.state(), sv::State::Recognise) << s.report().reason;
  const sv::RecognizeRequest request = outputs_of<sv::RecognizeRequest>(s.take_outputs()).at(0);
  s.on_recognition(request.seq, "", "no object matched 3 or more features", now_);
  const sv::NudgeCommand nudge = outputs_of<sv::NudgeCommand>(s.take_outputs()).at(0);
  ASSERT_LT((nudge.direction - direction).norm(), 1e-9);
  rest_ = object_ + 0.025 * nudge.direction;
  play_nudge(s, nudge.seq, object_, rest_, {neighbour});
  settle_with_axes(s, {neighbour});
  park(s);
  ASSERT_EQ(s.state(), sv::State::SnapshotAfter) << s.report().reason;
  s.take_outputs();
  both_stills(s, {neighbour, rest_});
  ASSERT_EQ(s.state(), sv::State::Grasp) << s.report().reason;
  const sv::GraspCommand grasp = outputs_of<sv::GraspCommand>(s.take_outputs()).at(0);
  EXPECT_LT((grasp.position - rest_).head<2>().norm(), 0.006) << "the rule moved the rest off the neighbour's axes";
  // The left segmentation ran about the neighbour's axes first (a line between the two objects,
  // 68 votes), then again about the new rest: the object's own line (122).
  ASSERT_EQ(left_after_lines.size(), 2u) << "run again about the moved rest";
  EXPECT_GT(left_after_lines.back().votes, 1.5 * left_after_lines.front().votes);
  const auto left_at_rest = scene_.left_axis_line(rest_, 0.25, {1280, 960});
  ASSERT_TRUE(left_at_rest);
  EXPECT_LT(std::abs(left_after_lines.back().r - left_at_rest->r), 20);
  // The 12 cm object's top, lowered by r tan(theta): fingers half way up it (the neighbour is
  // 2.5 cm tall).
  EXPECT_GT(grasp.height, 0.03);
  EXPECT_LT(grasp.height, 0.06);
}

TEST_F(LearningTest, AStableMismatchIsGraspedWhereTheMaskStandsAndPutBackWhereItStood) {
  for (const bool candidate_mismatched : {true, false}) {
  SCOPED_TRACE(candidate_mismatched ? "the candidate shares the mismatch" : "the candidate is right");
  Eigen::Vector3d truth = object_;
  auto cylinder = [&](bool left) {
    return [&, left](const cv::Mat&, const cv::Mat& after, const nudge::symmetry::Line&, const nudge::symmetry::Line&) {
      sv::Segmentation out;
      out.mask = cylinder_mask(scene_, after.size(), truth, 0.035, 0.12, left);
      return out;
    };
  };
  sv::Config config = drawn_config();
  config.learn = sv::Config::Learn::On;
  config.views = 1;
  sv::Supervisor s(config, scene_, sv::ArmSetup{}, cylinder(false));
  s.set_left_segmentation(cylinder(true));
  const Eigen::Vector3d mismatch = 0.05 * along_ray(object_);
  start_with(s, {candidate_mismatched ? Eigen::Vector3d(object_ + mismatch) : object_});
  stills(s, {object_});
  const auto request = outputs_of<sv::RecognizeRequest>(s.take_outputs()).at(0);
  s.on_recognition(request.seq, "", "empty database", now_);
  const auto nudge = outputs_of<sv::NudgeCommand>(s.take_outputs()).at(0);
  truth = object_ + 0.03 * nudge.direction;
  play_nudge(s, nudge.seq, object_, truth);
  settle_with_axes(s, {truth + mismatch});
  park(s);
  s.take_outputs();
  stills(s, {truth});
  ASSERT_EQ(s.state(), sv::State::Grasp) << s.report().reason;
  const auto grasp = outputs_of<sv::GraspCommand>(s.take_outputs()).at(0);
  EXPECT_LT((grasp.position - truth).head<2>().norm(), 0.005) << "where the mask stands";
  done(s, grasp.seq);
  now_ += kSecond / 5;
  s.on_right_still(draw_scene(scene_, {1280, 960}, {}), now_, now_);
  const auto commit = outputs_of<sv::LearnCommit>(s.take_outputs()).at(0);
  s.on_learned(commit.seq, true, "object_1", "", now_ += kSecond);
  ASSERT_EQ(s.state(), sv::State::Place) << s.report().reason;
  const auto place = outputs_of<sv::PlaceCommand>(s.take_outputs()).at(0);
  EXPECT_LT((place.position - object_).head<2>().norm(), 0.006) << "where it stood";
  }
}

TEST_F(LearningTest, AKnownObjectIsNotNudgedAndTheSummaryNamesIt) {
  sv::Supervisor s = make_learning();
  const sv::RecognizeRequest request = to_recognition(s);
  const auto projected = scene_.project_right(object_ + Eigen::Vector3d(0, 0, 0.05), {1280, 960});
  EXPECT_TRUE(request.roi.contains(cv::Point(*projected))) << "the candidate's region";
  EXPECT_EQ(request.image.size(), cv::Size(1280, 960));
  const cv::Mat match(40, 60, CV_8UC3, cv::Scalar(0, 0, 255));
  s.on_recognition(request.seq, "green bottle", "", now_ += kSecond, match);
  auto out = s.take_outputs();
  EXPECT_TRUE(outputs_of<sv::NudgeCommand>(out).empty());
  EXPECT_TRUE(outputs_of<sv::HomeCommand>(out).empty()) << "the arm never moved";
  const auto a = ended(out);
  ASSERT_TRUE(a);
  EXPECT_EQ(a->outcome, sv::Outcome::Known);
  EXPECT_EQ(a->recognised, "green bottle");
  EXPECT_EQ(a->recognition_match.size(), match.size()) << "the learner's match picture, for the attempt's folder";
  const std::string dir = testing::TempDir() + "/supervisor_known_" + std::to_string(::getpid());
  const std::string folder = sv::save_attempt(dir, *a, sv::ArmSetup{}, scene_.right_camera_in_world());
  EXPECT_EQ(cv::imread(folder + "/recognition_match.png").size(), match.size());
  std::filesystem::remove_all(dir);
  EXPECT_EQ(s.state(), sv::State::FindCandidates);
  answer_survey(s, {object_});  // the same candidate again: not asked twice
  EXPECT_EQ(s.state(), sv::State::Done);
  ASSERT_EQ(s.summary().known.size(), 1u);
  EXPECT_EQ(s.summary().known[0], "green bottle");
}

TEST_F(LearningTest, ASilentLearnerDoesNotStopTheNudge) {
  sv::Supervisor s = make_learning();
  to_recognition(s);
  s.on_time(now_ += 4 * kSecond);
  EXPECT_EQ(s.state(), sv::State::Recognise);
  s.on_time(now_ += 2 * kSecond);
  ASSERT_EQ(s.state(), sv::State::Nudge) << s.report().reason;
  EXPECT_EQ(outputs_of<sv::NudgeCommand>(s.take_outputs()).size(), 1u);
}

TEST_F(LearningTest, ALearnerSilentAfterTheViewsStillGetsTheObjectPutBack) {
  sv::Config few = drawn_config();  // 2 views suffice here
  few.learn = sv::Config::Learn::On;
  few.views = 2;
  sv::Supervisor s = make_learning(few);
  done(s, to_grasp(s).seq);
  for (int view = 0; view < 2; ++view) {
    now_ += kSecond / 5;
    s.on_right_still(draw_scene(scene_, {1280, 960}, {}), now_, now_);
    const auto turns = outputs_of<sv::RotateCommand>(s.take_outputs());
    if (view == 0) done(s, turns.at(0).seq);
  }
  ASSERT_EQ(s.state(), sv::State::Learn);
  s.on_time(now_ += 31 * kSecond);
  ASSERT_EQ(s.state(), sv::State::Place) << s.report().reason;
  done(s, outputs_of<sv::PlaceCommand>(s.take_outputs()).at(0).seq);
  const auto a = ended(s.take_outputs());
  ASSERT_TRUE(a);
  EXPECT_EQ(a->learning, "learner silent");
  EXPECT_NE(a->learning_reason.find("LEARNED"), std::string::npos) << a->learning_reason;
  EXPECT_EQ(s.summary().learned, 0);
}

// The learner learns on a worker thread and says so in its heartbeat: LEARN waits while it does
// (beyond --learn-timeout), up to --learn-max-wait; heartbeats about another object do not count.
TEST_F(LearningTest, LearnWaitsWhileTheLearnersHeartbeatSaysItLearnsTheObject) {
  sv::Config few = drawn_config();
  few.learn = sv::Config::Learn::On;
  few.views = 2;
  few.learn_timeout_s = 30;
  few.learn_max_wait_s = 100;
  for (const bool answered : {true, false}) {
    sv::Supervisor s = make_learning(few);
    done(s, to_grasp(s).seq);
    std::vector<sv::LearnCommit> commits;
    for (int view = 0; view < 2; ++view) {
      now_ += kSecond / 5;
      s.on_right_still(draw_scene(scene_, {1280, 960}, {}), now_, now_);
      const auto out = s.take_outputs();
      if (view == 0) done(s, outputs_of<sv::RotateCommand>(out).at(0).seq);
      if (view == 1) commits = outputs_of<sv::LearnCommit>(out);
    }
    ASSERT_EQ(s.state(), sv::State::Learn);
    ASSERT_EQ(commits.size(), 1u);
    const std::string key = commits[0].object_key;
    // 60 s of heartbeats saying it learns this object: still waiting, past learn_timeout_s.
    for (int beat = 1; beat <= 60; ++beat) {
      s.on_learner_status("learning " + key + " (view " + std::to_string(beat % 12 + 1) + "/12)", now_ += kSecond);
      s.on_learner_status("learning " + key + "9 (view 1/12)", now_);  // another object's key
      s.on_time(now_);
    }
    ASSERT_EQ(s.state(), sv::State::Learn) << s.report().reason;
    if (answered) {
      s.on_learned(commits[0].seq, true, "cereal", "", now_ += kSecond);
      ASSERT_EQ(s.state(), sv::State::Place) << s.report().reason;
      done(s, outputs_of<sv::PlaceCommand>(s.take_outputs()).at(0).seq);
      const auto a = ended(s.take_outputs());
      ASSERT_TRUE(a);
      EXPECT_EQ(a->learning, "learned");
      EXPECT_EQ(a->learned_name, "cereal");
      continue;
    }
    // Busy until the overall bound: then the object is put back with the reason.
    for (int beat = 61; beat <= 101 && s.state() == sv::State::Learn; ++beat) {
      s.on_learner_status("learning " + key + " (view 12/12)", now_ += kSecond);
      s.on_time(now_);
    }
    ASSERT_EQ(s.state(), sv::State::Place) << s.report().reason;
    done(s, outputs_of<sv::PlaceCommand>(s.take_outputs()).at(0).seq);
    const auto a = ended(s.take_outputs());
    ASSERT_TRUE(a);
    EXPECT_EQ(a->learning, "learner too slow");
    EXPECT_NE(a->learning_reason.find("--learn-max-wait"), std::string::npos) << a->learning_reason;
    EXPECT_NE(a->learning_reason.find(key), std::string::npos) << a->learning_reason;
  }
}

// A learner that stops saying it learns the object: learn_timeout_s after its last such heartbeat.
TEST_F(LearningTest, LearnEndsWhenTheLearnerStopsSayingItLearns) {
  sv::Config few = drawn_config();
  few.learn = sv::Config::Learn::On;
  few.views = 2;
  sv::Supervisor s = make_learning(few);
  done(s, to_grasp(s).seq);
  std::string key;
  for (int view = 0; view < 2; ++view) {
    now_ += kSecond / 5;
    s.on_right_still(draw_scene(scene_, {1280, 960}, {}), now_, now_);
    const auto out = s.take_outputs();
    if (view == 0) done(s, outputs_of<sv::RotateCommand>(out).at(0).seq);
    if (view == 1) key = outputs_of<sv::LearnCommit>(out).at(0).object_key;
  }
  ASSERT_EQ(s.state(), sv::State::Learn);
  s.on_learner_status("learning " + key + " (view 3/12)", now_ += 20 * kSecond);
  s.on_learner_status("ok", now_ += kSecond);  // idle: it forgot the object (restarted)
  s.on_time(now_ += 25 * kSecond);
  EXPECT_EQ(s.state(), sv::State::Learn) << "46 s after LEARN_COMMIT but 26 s after the busy heartbeat";
  s.on_time(now_ += 5 * kSecond);
  ASSERT_EQ(s.state(), sv::State::Place) << s.report().reason;
  done(s, outputs_of<sv::PlaceCommand>(s.take_outputs()).at(0).seq);
  const auto a = ended(s.take_outputs());
  ASSERT_TRUE(a);
  EXPECT_EQ(a->learning, "learner silent");
  EXPECT_NE(a->learning_reason.find("last heartbeat saying it was learning " + key), std::string::npos)
      << a->learning_reason;
}

TEST_F(LearningTest, ARefusedGraspEndsTheLearningWithTheArmsReason) {
  sv::Supervisor s = make_learning();
  const sv::GraspCommand grasp = to_grasp(s);
  s.on_arm_state(arm(sv::ArmStatus::Motion::Refused, grasp.seq, "grasp: wrist below the table"), now_ += kSecond);
  auto out = s.take_outputs();
  const auto a = ended(out);
  ASSERT_TRUE(a);
  EXPECT_EQ(a->outcome, sv::Outcome::Segmented) << "the segmentation stands";
  EXPECT_EQ(a->learning, "not grasped");
  EXPECT_NE(a->learning_reason.find("wrist below the table"), std::string::npos) << a->learning_reason;
  EXPECT_TRUE(outputs_of<sv::HomeCommand>(out).empty()) << "nothing moved";
  EXPECT_EQ(s.state(), sv::State::FindCandidates);
}

TEST_F(LearningTest, TheGraspIsPlannedOnTheStagelessSegmentationAndTheStagesAreDrawnAfterIt) {
  // The constructor's segmentation draws fig. 6.7's stages; the stageless one, given, is the one the
  // grasp waits for. The stages still reach the attempt's files, drawn once the grasp is commanded.
  std::vector<std::string> calls;
  auto with_stages = [&](const cv::Mat& before, const cv::Mat& after, const nudge::symmetry::Line& l0,
                         const nudge::symmetry::Line& l1) {
    calls.push_back("with stages");
    sv::Segmentation out = mask_of_difference(before, after, l0, l1);
    out.stages = {{"c_difference", cv::Mat(4, 4, CV_8U, cv::Scalar(7))}};
    return out;
  };
  auto stageless = [&](const cv::Mat& before, const cv::Mat& after, const nudge::symmetry::Line& l0,
                       const nudge::symmetry::Line& l1) {
    calls.push_back("stageless");
    return mask_of_difference(before, after, l0, l1);
  };
  sv::Config config = drawn_config();
  config.learn = sv::Config::Learn::On;
  sv::Supervisor s(config, scene_, sv::ArmSetup{}, with_stages);
  s.set_left_segmentation(mask_of_difference);
  s.set_stageless_segmentation(stageless);
  const sv::GraspCommand grasp = to_grasp(s);
  EXPECT_EQ(calls, (std::vector<std::string>{"stageless", "with stages"}));
  s.on_arm_state(arm(sv::ArmStatus::Motion::Refused, grasp.seq, "grasp: wrist below the table"), now_ += kSecond);
  const auto a = ended(s.take_outputs());
  ASSERT_TRUE(a);
  ASSERT_EQ(a->segmentation.stages.size(), 1u);
  EXPECT_EQ(a->segmentation.stages[0].first, "c_difference");
  EXPECT_GT(cv::countNonZero(a->segmentation.mask), 1000) << "the stageless segmentation's mask";
  EXPECT_GE(a->grasp_plan_ms, 0);
}

// The warm-up runs each segmentation once, the left one on a thread of its own, on a still pair of
// the configured size with a moved object between its lines, and leaves the run as it was.
TEST_F(LearningTest, TheWarmUpRunsEverySegmentationOnceOnStillsOfTheConfiguredSizeAndChangesNothing) {
  std::mutex lock;
  std::vector<std::string> calls;
  std::set<std::thread::id> threads;
  const auto counting = [&](const std::string& name) {
    return [&, name](const cv::Mat& before, const cv::Mat& after, const nudge::symmetry::Line& l0,
                     const nudge::symmetry::Line& l1) {
      {
        const std::lock_guard<std::mutex> hold(lock);
        calls.push_back(name + " " + std::to_string(after.cols) + "x" + std::to_string(after.rows));
        threads.insert(std::this_thread::get_id());
      }
      EXPECT_EQ(before.size(), after.size());
      EXPECT_GT(l1.r, l0.r) << "the object moved right between the lines";
      return mask_of_difference(before, after, l0, l1);
    };
  };
  sv::Config config = drawn_config();
  config.learn = sv::Config::Learn::On;
  sv::Supervisor s(config, scene_, sv::ArmSetup{}, counting("right"));
  s.set_left_segmentation(counting("left"));
  s.set_stageless_segmentation(counting("stageless"));
  const sv::State state = s.state();
  s.warm_up();
  std::sort(calls.begin(), calls.end());
  const std::string size = std::to_string(config.still_size.width) + "x" + std::to_string(config.still_size.height);
  EXPECT_EQ(calls, (std::vector<std::string>{"left " + size, "right " + size, "stageless " + size}));
  EXPECT_EQ(threads.size(), 2u) << "the left camera's on a thread of its own";
  EXPECT_TRUE(s.take_outputs().empty());
  EXPECT_EQ(s.state(), state);
  EXPECT_EQ(s.summary().attempts, 0);
}

// Closed to 1 mm: missed, or pinching a thin part (a cup's wall between the fingers). The fingers
// open again where they closed, down at the grasp height, before the arm parks.
TEST_F(LearningTest, AGripperThatClosesFullyHoldsNothingAndOpensWhereItClosed) {
  sv::Supervisor s = make_learning();
  const sv::GraspCommand grasp = to_grasp(s);
  done(s, grasp.seq, 0.001);
  auto out = s.take_outputs();
  EXPECT_TRUE(outputs_of<sv::AttemptEnded>(out).empty()) << "not before the fingers have opened";
  const auto put_down = outputs_of<sv::PlaceCommand>(out);
  ASSERT_EQ(put_down.size(), 1u);
  EXPECT_LT((put_down[0].position - grasp.position).norm(), 1e-9) << "where the fingers closed";
  EXPECT_DOUBLE_EQ(put_down[0].height, grasp.height);
  done(s, put_down[0].seq);
  out = s.take_outputs();
  auto a = ended(out);
  ASSERT_TRUE(a);
  EXPECT_EQ(a->learning, "dropped");
  EXPECT_NE(a->learning_reason.find("after the grasp"), std::string::npos) << a->learning_reason;
  EXPECT_EQ(outputs_of<sv::HomeCommand>(out).size(), 1u) << "the arm parks";
}

// The demo's mug, grasped 3 cm off its axis: a finger came down on its rim and the fingers were
// held apart wider than they open (0.128 m); the mug hung on its side. Fingers closed far
// narrower than the object is wide pinch an edge. Either is put down again where the fingers
// closed, not learned.
TEST_F(LearningTest, AGripFarWiderOrNarrowerThanTheObjectIsPutDownNotLearned) {
  for (const double opening : {0.128, 0.02}) {
    SCOPED_TRACE(opening);
    sv::Supervisor s = make_learning();
    const sv::GraspCommand grasp = to_grasp(s);
    done(s, grasp.seq, opening);
    auto out = s.take_outputs();
    EXPECT_TRUE(outputs_of<sv::RotateCommand>(out).empty() && outputs_of<sv::SnapshotRequest>(out).empty()) << "no view";
    const auto put_down = outputs_of<sv::PlaceCommand>(out);
    ASSERT_EQ(put_down.size(), 1u) << s.report().reason;
    EXPECT_LT((put_down[0].position - grasp.position).norm(), 1e-9) << "where the fingers closed";
    done(s, put_down[0].seq);
    const auto a = ended(s.take_outputs());
    ASSERT_TRUE(a);
    EXPECT_EQ(a->learning, "not grasped");
    EXPECT_NE(a->learning_reason.find("off its axis"), std::string::npos) << a->learning_reason;
    ASSERT_TRUE(a->expected_grip_width_m);
    // The test's box is 7 cm wide, seen a little obliquely.
    EXPECT_NEAR(*a->expected_grip_width_m, 0.07, 0.012);
    EXPECT_DOUBLE_EQ(a->grip_opening_m, opening);
  }
}

TEST_F(LearningTest, AnObjectDroppedWhileTurningIsNoticedAndTheRunGoesOn) {
  sv::Supervisor s = make_learning();
  done(s, to_grasp(s).seq);
  now_ += kSecond / 5;
  s.on_right_still(draw_scene(scene_, {1280, 960}, {}), now_, now_);
  const auto turn = outputs_of<sv::RotateCommand>(s.take_outputs()).at(0);
  done(s, turn.seq, 0.0);  // slipped out during the turn
  auto out = s.take_outputs();
  auto a = ended(out);
  ASSERT_TRUE(a);
  EXPECT_EQ(a->learning, "dropped");
  EXPECT_NE(a->learning_reason.find("after turn 1"), std::string::npos) << a->learning_reason;
  EXPECT_TRUE(outputs_of<sv::LearnCommit>(out).empty());
  park(s);
  EXPECT_EQ(s.state(), sv::State::FindCandidates);
  EXPECT_EQ(s.summary().learning.at("dropped"), 1);
}

TEST_F(LearningTest, AutoLearnsOnlyWhileTheLearnerIsHeard) {
  sv::Config config = drawn_config();
  config.learn = sv::Config::Learn::Auto;
  sv::Supervisor s = make(config);
  auto out = start_with(s, {object_});
  EXPECT_FALSE(outputs_of<sv::SnapshotRequest>(out).at(0).both) << "no learner: segmentation only";
  sv::Supervisor heard = make(config);
  heard.set_learner_alive(true);
  out = start_with(heard, {object_});
  EXPECT_TRUE(outputs_of<sv::SnapshotRequest>(out).at(0).both);
}

TEST_F(LearningTest, TheViewsTheLeftStillsAndTheLearningAreSavedBesideTheAttempt) {
  sv::Supervisor s = make_learning();
  done(s, to_grasp(s).seq);
  now_ += kSecond / 5;
  s.on_right_still(draw_scene(scene_, {1280, 960}, {}), now_, now_);
  auto out = s.take_outputs();
  const auto view = outputs_of<sv::LearnView>(out).at(0);
  done(s, outputs_of<sv::RotateCommand>(out).at(0).seq);
  const std::string dir = testing::TempDir() + "/supervisor_views_" + std::to_string(::getpid());
  std::filesystem::remove_all(dir);
  const std::string file = sv::save_view(dir, 1, view);
  EXPECT_EQ(file, dir + "/attempt_01/views/view_00.png");
  EXPECT_TRUE(std::filesystem::exists(file));
  s.on_time(now_ += 11 * kSecond);  // the next still never comes: the object is put back
  ASSERT_EQ(s.state(), sv::State::Place) << s.report().reason;
  done(s, outputs_of<sv::PlaceCommand>(s.take_outputs()).at(0).seq);
  const auto a = ended(s.take_outputs());
  ASSERT_TRUE(a);
  EXPECT_EQ(a->learning, "snapshot lost");
  const std::string folder = sv::save_attempt(dir, *a, sv::ArmSetup{}, scene_.right_camera_in_world());
  for (const char* name : {"before.png", "after.png", "mask.png", "before_left.png", "after_left.png", "mask_left.png", "attempt.json"})
    EXPECT_TRUE(std::filesystem::exists(folder + "/" + name)) << name;
  // The cut-out is made where it is written: the after still where the mask is set, black elsewhere.
  const cv::Mat cutout = cv::imread(folder + "/cutout.png", cv::IMREAD_COLOR);
  ASSERT_EQ(cutout.size(), a->after.size());
  cv::Mat expected = cv::Mat::zeros(a->after.size(), a->after.type());
  a->after.copyTo(expected, a->segmentation.mask);
  EXPECT_EQ(cv::norm(cutout, expected, cv::NORM_INF), 0);
  EXPECT_GT(cv::countNonZero(a->segmentation.mask), 0);
  std::ifstream in(folder + "/attempt.json");
  const std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(json.find("\"learning\":{\"outcome\":\"snapshot lost\""), std::string::npos) << json.substr(0, 400);
  EXPECT_NE(json.find("\"grasp_height_m\""), std::string::npos);
  std::filesystem::remove_all(dir);
}

// A 1280x960 still of what fooled the after line's search in a held-out run: the arm's base column
// (light, standing from the top of the image to row 330) and in front of it a bottle (dark, rows
// 240-560, its base an ellipse) whose axis is 25 px left of the column's. The prediction is the column's axis, with its
// foot at the bottle's foot row.
struct ColumnAndBottle {
  cv::Mat still{960, 1280, CV_8UC3, cv::Scalar(128, 128, 128)};
  double column_x = 640, bottle_x = 615;
  sv::LineSearchParams params;
  ColumnAndBottle(bool with_bottle = true) {
    cv::rectangle(still, cv::Point(560, 0), cv::Point(720, 330), cv::Scalar(210, 210, 210), cv::FILLED);
    if (!with_bottle) return;
    // A bottle's outline ends in the ellipse of its base, not in a straight edge.
    const cv::Scalar dark(50, 60, 70);
    cv::rectangle(still, cv::Point(560, 240), cv::Point(670, 540), dark, cv::FILLED);
    cv::ellipse(still, cv::Point(615, 540), cv::Size(55, 20), 0, 0, 360, dark, cv::FILLED);
  }
  nudge::symmetry::Line predicted(bool with_span) const {
    const cv::Point2d foot(column_x, 560), top(column_x, 240);
    nudge::symmetry::Line line = sv::line_through(foot, top, still.size());
    if (with_span) {
      line.seg1 = foot;
      line.seg2 = top;
    }
    return line;
  }
  // The found line's x at the bottle's middle row.
  double found_x(const nudge::symmetry::Line& line) const {
    const double c = std::cos(line.theta), s = std::sin(line.theta);
    const cv::Point2d centre((still.cols - 1) / 2.0, (still.rows - 1) / 2.0);
    const double y = 400 - centre.y;
    return centre.x + (line.r - y * s) / c;
  }
};

TEST(LineSearch, TakesTheLineThatStandsOnThePredictedFootOverANearerOneEndingAboveIt) {
  const ColumnAndBottle scene;
  const auto found = sv::find_line_near(scene.still, scene.predicted(true), scene.params);
  ASSERT_TRUE(found);
  EXPECT_NEAR(scene.found_x(*found), scene.bottle_x, 3.0);
  // Without the predicted foot, the nearest line is taken: the column's (or the column and bottle's).
  const auto nearest = sv::find_line_near(scene.still, scene.predicted(false), scene.params);
  ASSERT_TRUE(nearest);
  EXPECT_NEAR(scene.found_x(*nearest), scene.column_x, 3.0);
}

// An object 20 px and 5 deg off its predicted axis, near the still's edge, and a symmetric object far
// away: the search in the band about the prediction finds the object's line, as the search of the
// whole still does, in the whole still's coordinates.
TEST(LineSearch, TheSearchOfTheBandAboutThePredictionFindsTheLineTheWholeStillShows) {
  cv::Mat still(960, 1280, CV_8UC3, cv::Scalar(150, 150, 150));
  const double theta = 5 * M_PI / 180;
  const cv::Point2d centre(1000, 500), along(-std::sin(theta), std::cos(theta)), across(std::cos(theta), std::sin(theta));
  std::vector<cv::Point> outline;
  for (const cv::Point2d& corner : {centre - 200 * along - 60 * across, centre - 200 * along + 60 * across,
                                    centre + 200 * along + 60 * across, centre + 200 * along - 60 * across})
    outline.emplace_back(cvRound(corner.x), cvRound(corner.y));
  cv::fillConvexPoly(still, outline, cv::Scalar(40, 60, 80));
  cv::rectangle(still, cv::Rect(200, 250, 140, 420), cv::Scalar(230, 230, 230), cv::FILLED);
  const cv::Point2d foot(980, 720), top(980, 280);
  nudge::symmetry::Line predicted = sv::line_through(foot, top, still.size());
  predicted.seg1 = foot;
  predicted.seg2 = top;
  sv::LineSearchParams params;
  const cv::Rect region = sv::search_region(still.size(), predicted, params);
  EXPECT_LT(region.area(), still.size().area() / 2);
  EXPECT_TRUE(region.contains(cv::Point(cvRound(centre.x), cvRound(centre.y))));
  const auto cropped = sv::find_line_near(still, predicted, params);
  params.crop_to_prediction = false;
  const auto whole = sv::find_line_near(still, predicted, params);
  ASSERT_TRUE(cropped);
  ASSERT_TRUE(whole);
  const cv::Point2d image_centre((still.cols - 1) / 2.0, (still.rows - 1) / 2.0);
  const auto distance = [&](const nudge::symmetry::Line& line) {
    return std::abs((centre - image_centre).dot(cv::Point2d(std::cos(line.theta), std::sin(line.theta))) - line.r);
  };
  EXPECT_LT(distance(*cropped), 1.5);
  EXPECT_NEAR(cropped->theta, theta, 0.5 * M_PI / 180);
  EXPECT_NEAR(cropped->r, whole->r, 0.5);
  EXPECT_NEAR(cropped->theta, whole->theta, 0.2 * M_PI / 180);
  EXPECT_LT(cv::norm(cropped->seg1 - whole->seg1) + cv::norm(cropped->seg2 - whole->seg2), 4.0);
}

// A prediction without a span, or one off the still: the whole still, or nothing to search.
TEST(LineSearch, TheBandIsTheWholeStillWithoutASpanAndEmptyOffIt) {
  const cv::Size size(1280, 960);
  nudge::symmetry::Line spanless = sv::line_through({640, 700}, {640, 300}, size);
  spanless.seg1 = spanless.seg2 = {640, 500};
  EXPECT_EQ(sv::search_region(size, spanless), cv::Rect(0, 0, 1280, 960));
  nudge::symmetry::Line off = sv::line_through({5000, 700}, {5000, 300}, size);
  off.seg1 = {5000, 700};
  off.seg2 = {5000, 300};
  EXPECT_TRUE(sv::search_region(size, off).empty());
  EXPECT_FALSE(sv::find_line_near(cv::Mat(size, CV_8UC3, cv::Scalar::all(100)), off));
}

// A still taken earlier tells a line that stood there from one that arrived: the share of pixels
// about the line that changed. Two bars: one stands still, the other arrives where nothing stood.
TEST(LineSearch, AnEarlierStillPassesOverTheLineThatStoodThereAndKeepsTheOneThatArrived) {
  cv::Mat earlier(960, 1280, CV_8UC3, cv::Scalar(128, 128, 128));
  // The standing bar is the taller: more rows vote for it.
  cv::rectangle(earlier, cv::Point(400, 200), cv::Point(480, 700), cv::Scalar(40, 50, 60), cv::FILLED);
  cv::Mat later = earlier.clone();
  cv::rectangle(later, cv::Point(560, 300), cv::Point(640, 700), cv::Scalar(200, 60, 40), cv::FILLED);  // arrives
  const cv::Size size = later.size();
  auto standing = sv::line_through({440, 700}, {440, 300}, size);
  auto arrived = sv::line_through({600, 700}, {600, 300}, size);
  EXPECT_NEAR(sv::changed_share(earlier, later, arrived, 25, 25), 400.0 / 960, 0.01) << "along the whole image's span";
  standing.seg1 = {440, 700}, standing.seg2 = {440, 300};  // along the bars' height
  arrived.seg1 = {600, 700}, arrived.seg2 = {600, 300};
  EXPECT_EQ(sv::changed_share(earlier, later, standing, 25, 25), 0);
  EXPECT_GT(sv::changed_share(earlier, later, arrived, 25, 25), 0.9);
  EXPECT_EQ(sv::changed_share(cv::Mat(480, 640, CV_8UC3), later, arrived, 25, 25), 0) << "stills of different sizes";
  // Searched for midway between the two, within reach of both: the standing bar's line is taken
  // without the earlier still, the arriving one's with it.
  sv::LineSearchParams params;
  params.window_px = 100;
  const auto midway = sv::line_through({520, 700}, {520, 300}, size);
  const auto without = sv::find_line_near(later, midway, params);
  const auto with = sv::find_line_near(later, midway, params, {}, earlier);
  ASSERT_TRUE(without && with);
  EXPECT_LT(std::abs(nudge::symmetry::line_difference(*without, standing).r), 3);
  EXPECT_LT(std::abs(nudge::symmetry::line_difference(*with, arrived).r), 3);
  EXPECT_THROW(sv::find_line_near(later, midway, params, {}, cv::Mat(480, 640, CV_8UC3)), std::invalid_argument);
}

// A dark bottle 25 px beside the prediction and, at the prediction, a short faint pair of stripes
// (an object's edge paired with something behind it): the nearest line is the stripes', the
// strongest the bottle's.
TEST(LineSearch, TheStrongestPickTakesTheBottleOverAFaintPairAtThePrediction) {
  cv::Mat still(960, 1280, CV_8UC3, cv::Scalar(128, 128, 128));
  cv::rectangle(still, cv::Point(560, 240), cv::Point(670, 540), cv::Scalar(50, 60, 70), cv::FILLED);
  for (int x : {600, 680}) cv::line(still, cv::Point(x, 590), cv::Point(x, 660), cv::Scalar(170, 170, 170), 3);
  const nudge::symmetry::Line predicted = sv::line_through({640, 700}, {640, 240}, still.size());  // no span
  const auto x_at = [&](const nudge::symmetry::Line& line, double row) {
    const cv::Point2d centre((still.cols - 1) / 2.0, (still.rows - 1) / 2.0);
    return centre.x + (line.r - (row - centre.y) * std::sin(line.theta)) / std::cos(line.theta);
  };
  sv::LineSearchParams params;
  params.strongest = false;
  const auto nearest = sv::find_line_near(still, predicted, params);
  ASSERT_TRUE(nearest);
  EXPECT_NEAR(x_at(*nearest, 620), 640, 3.0);
  params.strongest = true;  // the default
  const auto strongest = sv::find_line_near(still, predicted, params);
  ASSERT_TRUE(strongest);
  EXPECT_NEAR(x_at(*strongest, 400), 615, 3.0);
  EXPECT_GT(strongest->votes, 2 * nearest->votes);
}

TEST(LineSearch, APredictionTurnedAboutItsFootKeepsTheFootAndTurnsTheAngle) {
  const cv::Size size(1280, 960);
  nudge::symmetry::Line upright = sv::line_through({700, 600}, {690, 250}, size);
  upright.seg1 = {700, 600};
  upright.seg2 = {690, 250};
  for (double degrees : {-5.0, 3.0}) {
    const nudge::symmetry::Line turned = sv::turned_about_foot(upright, degrees * M_PI / 180, size);
    EXPECT_NEAR(nudge::symmetry::line_difference(turned, upright).theta * 180 / M_PI, degrees, 1e-6);
    EXPECT_EQ(turned.seg1, upright.seg1);
    EXPECT_NEAR(cv::norm(turned.seg2 - turned.seg1), cv::norm(upright.seg2 - upright.seg1), 1e-6);
    EXPECT_NEAR(sv::signed_distance(turned, turned.seg1, size), 0, 1e-6);
    EXPECT_NEAR(sv::signed_distance(turned, turned.seg2, size), 0, 1e-6);
  }
}

// A bottle that leans 5 deg in the before still and in the after one, where a taller upright pair of
// stripes stands on it at the upright prediction of the rest (as the arm's base column's outline
// behind a clear bottle): the strongest line about the upright prediction is the stripes', the
// strongest about the before line's lean carried over is the bottle's.
TEST(LineSearch, TheMovedObjectsLineKeepsTheLeanItHadBeforeTheNudge) {
  const cv::Size size(1280, 960);
  const double lean = 5 * M_PI / 180;
  const auto leaning_bottle = [&](cv::Mat& still, cv::Point2d foot) {
    const cv::Point2d up(std::sin(lean), -std::cos(lean)), across(std::cos(lean), std::sin(lean));
    std::vector<cv::Point> outline;
    for (const cv::Point2d& corner : {foot - 55 * across, foot + 55 * across, foot + 55 * across + 320 * up, foot - 55 * across + 320 * up})
      outline.emplace_back(cvRound(corner.x), cvRound(corner.y));
    cv::fillConvexPoly(still, outline, cv::Scalar(50, 60, 70));
  };
  const auto upright_at = [&](cv::Point2d foot) {
    nudge::symmetry::Line line = sv::line_through(foot, foot + cv::Point2d(0, -320), size);
    line.seg1 = foot;
    line.seg2 = foot + cv::Point2d(0, -320);
    return line;
  };
  cv::Mat before(size, CV_8UC3, cv::Scalar(128, 128, 128)), after = before.clone();
  leaning_bottle(before, {500, 600});
  leaning_bottle(after, {640, 600});
  for (int x : {628, 708}) cv::line(after, cv::Point(x, 150), cv::Point(x, 600), cv::Scalar(200, 200, 200), 3);
  sv::LineSearchParams params;  // the defaults: the strongest line, a lean window of 2 deg
  const nudge::symmetry::Line predicted_before = upright_at({500, 600}), predicted_after = upright_at({668, 600});
  const auto before_line = sv::find_line_near(before, predicted_before, params);
  ASSERT_TRUE(before_line);
  EXPECT_NEAR(before_line->theta, lean, 1 * M_PI / 180);
  const auto moved = sv::find_moved_line(after, predicted_after, predicted_before, before_line, params);
  ASSERT_TRUE(moved);
  EXPECT_NEAR(moved->theta, lean, 1 * M_PI / 180);
  EXPECT_NEAR(sv::signed_distance(*moved, {640, 600}, size), 0, 3.0);  // through the bottle's foot
  // Without the lean, or without a before line: the stripes' upright line.
  for (const bool knows_before : {true, false}) {
    params.lean_window_deg = knows_before ? 0 : 2;
    const auto upright = sv::find_moved_line(after, predicted_after, predicted_before,
                                             knows_before ? before_line : std::nullopt, params);
    ASSERT_TRUE(upright);
    EXPECT_NEAR(upright->theta, 0, 1 * M_PI / 180) << knows_before;
    EXPECT_NEAR(sv::signed_distance(*upright, {668, 400}, size), 0, 3.0) << knows_before;
  }
}

// A bright column standing from the still's top down to the bottle's foot, 20 px beside a fainter
// bottle: the column's line is the strongest in the window; given as not an object's, it is passed
// over, unless the prediction lies on it (the object in line with the column: its line is the one).
TEST(LineSearch, TheArmBaseColumnsLineIsPassedOverUnlessThePredictionLiesOnIt) {
  cv::Mat still(960, 1280, CV_8UC3, cv::Scalar(128, 128, 128));
  cv::rectangle(still, cv::Point(560, 0), cv::Point(720, 560), cv::Scalar(230, 230, 230), cv::FILLED);
  cv::rectangle(still, cv::Point(575, 300), cv::Point(665, 560), cv::Scalar(150, 150, 150), cv::FILLED);
  const auto upright_at = [&](double x) {
    nudge::symmetry::Line line = sv::line_through({x, 560}, {x, 240}, still.size());
    line.seg1 = {x, 560};
    line.seg2 = {x, 240};
    return line;
  };
  const nudge::symmetry::Line column = upright_at(640);
  const sv::LineSearchParams params;
  const auto strongest = sv::find_line_near(still, upright_at(630), params);
  ASSERT_TRUE(strongest);
  EXPECT_NEAR(sv::signed_distance(*strongest, {640, 400}, still.size()), 0, 3.0);  // the column's
  const auto object = sv::find_line_near(still, upright_at(630), params, {column});
  ASSERT_TRUE(object);
  EXPECT_NEAR(sv::signed_distance(*object, {620, 400}, still.size()), 0, 3.0);  // the bottle's
  const auto in_line = sv::find_line_near(still, upright_at(642), params, {column});
  ASSERT_TRUE(in_line);
  EXPECT_NEAR(sv::signed_distance(*in_line, {640, 400}, still.size()), 0, 3.0);
}

TEST(LineSearch, TakesTheNearestLineWhenNoneReachesTheFoot) {
  const ColumnAndBottle scene(/*with_bottle=*/false);
  const auto found = sv::find_line_near(scene.still, scene.predicted(true), scene.params);
  ASSERT_TRUE(found);
  EXPECT_NEAR(scene.found_x(*found), scene.column_x, 3.0);
}

// The lines attempt.json records read back as written (a small angle in exponent form included);
// an absent or null line is nothing.
TEST(RecordedLine, ReadsBackTheLinesAttemptJsonWrote) {
  sv::Attempt a;
  a.number = 3;
  nudge::symmetry::Line before, after;
  before.r = -98.8212093;
  before.theta = -0.118284486;
  before.votes = 195;
  after.r = 412.5;
  after.theta = 1.5e-07;
  after.votes = 1234567;
  a.before_line = before;
  a.after_line = after;
  const std::string json = sv::attempt_json(a);
  const auto read_before = sv::recorded_line(json, "line_before"), read_after = sv::recorded_line(json, "line_after");
  ASSERT_TRUE(read_before && read_after) << json;
  EXPECT_NEAR(read_before->r, before.r, 1e-4);
  EXPECT_NEAR(read_before->theta, before.theta, 1e-8);
  EXPECT_NEAR(read_before->votes, 195, 1e-9);
  EXPECT_NEAR(read_after->r, after.r, 1e-4);
  EXPECT_NEAR(read_after->theta, after.theta, 1e-12);
  EXPECT_NEAR(read_after->votes, after.votes, 10.0) << "six significant digits: 1.23457e+06";
  EXPECT_FALSE(sv::recorded_line(json, "line_before_left"));
  EXPECT_FALSE(sv::recorded_line("{}", "line_after"));
}
