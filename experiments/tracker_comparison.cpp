// The symmetry tracker against three appearance trackers on the simulated test videos of
// nudge-exp-tracking-videos: OpenCV's CSRT and KCF (contrib `tracking` module) and a CamShift
// colour tracker (hue-saturation histogram back-projection). The appearance trackers all start
// from the same box, the target's true mask bounding box in frame 0; the symmetry tracker starts
// itself (automatic start on the first motion).
//   nudge-exp-tracker-comparison [--frames N] [--camera 0] [--only NAME]
// Accuracy = distance (px) from the tracker's box centre to the target's true axis line;
// for the symmetry tracker, from the centre of its rotated box moved onto its own line (it claims
// the object is centred on that line). Loss = a scored frame where the tracker reports failure or
// is more than 30 px off. Scored frames: from three frames after the target first moves (the
// symmetry tracker's automatic start needs them) to the end.
// Writes docs/results/tracker_comparison.{json,md} and tracker_comparison_errors.png.
#include <cmath>
#include <iostream>
#include <map>
#include <sstream>

#include <opencv2/imgproc.hpp>
#include <opencv2/tracking.hpp>
#include <opencv2/video/tracking.hpp>

#include "nudge/flags.hpp"
#include "nudge/json.hpp"
#include "nudge/timing.hpp"
#include "nudge/tracking/tracker.hpp"
#include "report.hpp"
#include "tracking_scenarios.hpp"

using namespace nudge;
using namespace nudge::experiments;
namespace trk = nudge::tracking;

namespace {

constexpr double kLossPx = 30.0;
const std::vector<std::string> kTrackers = {"symmetry", "csrt", "kcf", "camshift"};

// One tracker's answer for a frame: a point that should lie on the target's axis, or failure.
struct Answer {
  bool ok = false;
  cv::Point2d centre;
};

class Follower {
 public:
  virtual ~Follower() = default;
  // `mask`: the target's true pixels in the first frame (only the colour tracker uses them).
  virtual void init(const cv::Mat& frame, const cv::Rect& box, const cv::Mat& mask) = 0;
  virtual Answer update(const cv::Mat& frame, int k) = 0;
};

class SymmetryFollower : public Follower {
 public:
  void init(const cv::Mat& frame, const cv::Rect&, const cv::Mat&) override { tracker_.feed(frame, 0); }
  Answer update(const cv::Mat& frame, int k) override {
    const trk::TrackState s = tracker_.feed(frame, static_cast<int64_t>(k) * 40000);
    Answer a;
    if (s.status != trk::TrackStatus::Tracking || !s.has_box) return a;
    cv::Point2d c(0, 0);
    for (const auto& p : s.box) c += 0.25 * p;
    // Onto the tracker's own line: (x - cx) cos t + (y - cy) sin t = r.
    const cv::Point2d centre(0.5 * (frame.cols - 1), 0.5 * (frame.rows - 1));
    const cv::Point2d n(std::cos(s.line.theta), std::sin(s.line.theta));
    const double off = (c - centre).dot(n) - s.line.r;
    a.ok = true;
    a.centre = c - off * n;
    return a;
  }

 private:
  trk::SymmetryTracker tracker_;
};

class OpenCvFollower : public Follower {
 public:
  explicit OpenCvFollower(cv::Ptr<cv::Tracker> tracker) : tracker_(std::move(tracker)) {}
  void init(const cv::Mat& frame, const cv::Rect& box, const cv::Mat&) override { tracker_->init(frame, box); }
  Answer update(const cv::Mat& frame, int) override {
    cv::Rect box;
    Answer a;
    a.ok = tracker_->update(frame, box) && box.area() > 0;
    a.centre = cv::Point2d(box.x + 0.5 * box.width, box.y + 0.5 * box.height);
    return a;
  }

 private:
  cv::Ptr<cv::Tracker> tracker_;
};

// CamShift on the back-projection of a hue-saturation histogram (45 x 8 bins, as the thesis'
// colour tracker, sec. 5.4.3) of the first box; V rejects very dark and very bright pixels, S
// rejects nearly grey ones (their hue is noise). The histogram is made from the target's true
// pixels in the first box (a best-case colour model, like the thesis' hand-optimised one).
class CamShiftFollower : public Follower {
 public:
  void init(const cv::Mat& frame, const cv::Rect& box, const cv::Mat& target) override {
    cv::Mat hsv, mask;
    convert(frame, &hsv, &mask);
    mask &= target;  // the colour model of the object only (the thesis' hand-made histogram)
    const int channels[] = {0, 1};
    const int sizes[] = {45, 8};
    const float h_range[] = {0, 180}, s_range[] = {0, 256};
    const float* ranges[] = {h_range, s_range};
    cv::Mat roi(hsv, box), roi_mask(mask, box);
    cv::calcHist(&roi, 1, channels, roi_mask, hist_, 2, sizes, ranges);
    cv::normalize(hist_, hist_, 0, 255, cv::NORM_MINMAX);
    window_ = box;
  }
  Answer update(const cv::Mat& frame, int) override {
    cv::Mat hsv, mask, back;
    convert(frame, &hsv, &mask);
    const int channels[] = {0, 1};
    const float h_range[] = {0, 180}, s_range[] = {0, 256};
    const float* ranges[] = {h_range, s_range};
    cv::calcBackProject(&hsv, 1, channels, hist_, back, ranges);
    back &= mask;
    Answer a;
    const cv::Rect before = window_;
    const cv::RotatedRect r =
        cv::CamShift(back, window_, cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 10, 1));
    if (window_.area() <= 1 || r.size.area() <= 1) {
      window_ = before;  // collapsed: report failure and search the old window again
      return a;
    }
    a.ok = true;
    a.centre = r.center;
    return a;
  }

 private:
  static void convert(const cv::Mat& frame, cv::Mat* hsv, cv::Mat* mask) {
    cv::cvtColor(frame, *hsv, cv::COLOR_BGR2HSV);
    cv::inRange(*hsv, cv::Scalar(0, 40, 32), cv::Scalar(180, 256, 245), *mask);
  }
  cv::Mat hist_;
  cv::Rect window_;
};

std::unique_ptr<Follower> make_follower(const std::string& name) {
  if (name == "symmetry") return std::make_unique<SymmetryFollower>();
  if (name == "csrt") return std::make_unique<OpenCvFollower>(cv::TrackerCSRT::create());
  if (name == "kcf") return std::make_unique<OpenCvFollower>(cv::TrackerKCF::create());
  return std::make_unique<CamShiftFollower>();
}

struct Score {
  std::vector<double> errors;  // scored frames with an answer
  int scored = 0, losses = 0, updates = 0;
  double ms = 0;
  std::vector<double> frame, error;  // for the plot (answered scored frames)
  void add(const Score& o) {
    errors.insert(errors.end(), o.errors.begin(), o.errors.end());
    scored += o.scored;
    losses += o.losses;
    updates += o.updates;
    ms += o.ms;
  }
  double mean_error() const { return errors.empty() ? NAN : mean(errors); }
  double fps() const { return ms > 0 ? 1000.0 * updates / ms : NAN; }
};

struct VideoScores {
  std::string name;
  int frames = 0, first_scored = 0;
  std::map<std::string, Score> by_tracker;
};

VideoScores run_video(const Scenario& sc, int camera, int max_frames) {
  const Video video = render_video(sc, camera, max_frames);
  VideoScores vs;
  vs.name = sc.name;
  vs.frames = static_cast<int>(video.frames.size());
  int motion = 0;
  while (motion < vs.frames && !video.frames[motion].target_moving) ++motion;
  vs.first_scored = motion + 3;
  const int w = video.frames[0].image.cols, h = video.frames[0].image.rows;
  for (const std::string& name : kTrackers) {
    auto follower = make_follower(name);
    Score score;
    follower->init(video.frames[0].image, video.first_box, video.first_mask);
    for (int k = 1; k < vs.frames; ++k) {
      const VideoFrame& f = video.frames[k];
      Stopwatch watch;
      const Answer a = follower->update(f.image, k);
      score.ms += watch.elapsed_ms();
      ++score.updates;
      if (k < vs.first_scored) continue;
      ++score.scored;
      if (!a.ok) {
        ++score.losses;
        continue;
      }
      const double e = distance_to_line(a.centre, f.truth, w, h);
      score.errors.push_back(e);
      score.frame.push_back(k);
      score.error.push_back(e);
      if (e > kLossPx) ++score.losses;
    }
    std::cout << sc.name << " " << name << ": mean error " << score.mean_error() << " px, losses " << score.losses
              << "/" << score.scored << ", " << score.fps() << " fps\n";
    vs.by_tracker[name] = std::move(score);
  }
  return vs;
}

std::string num(double v) {  // for tables: "–" for a tracker that never answered
  if (!std::isfinite(v)) return "–";
  std::ostringstream o;
  if (std::abs(v) >= 100) {
    o << std::fixed;
    o.precision(0);
  } else {
    o.precision(3);
  }
  o << v;
  return o.str();
}

void write_results(const std::vector<VideoScores>& videos, int camera) {
  std::map<std::string, Score> total;
  for (const auto& v : videos)
    for (const auto& [name, s] : v.by_tracker) total[name].add(s);
  JsonWriter j;
  j.begin_object();
  j.field("machine", machine_description()).field("date", today()).field("camera", camera);
  j.field("loss_px", kLossPx);
  for (const std::string& name : kTrackers) {
    const Score& s = total[name];
    j.key(name).begin_object();
    j.field("mean_error_px", s.mean_error()).field("median_error_px", s.errors.empty() ? NAN : median(s.errors));
    j.field("losses", s.losses).field("scored_frames", s.scored).field("fps", s.fps());
    j.end_object();
  }
  j.key("videos").begin_array();
  for (const auto& v : videos) {
    j.begin_object();
    j.field("name", v.name).field("frames", v.frames).field("first_scored_frame", v.first_scored);
    for (const std::string& name : kTrackers) {
      const Score& s = v.by_tracker.at(name);
      j.key(name).begin_object();
      j.field("mean_error_px", s.mean_error()).field("losses", s.losses).field("scored_frames", s.scored);
      j.field("fps", s.fps());
      j.end_object();
    }
    j.end_object();
  }
  j.end_array();
  j.end_object();
  write_result("tracker_comparison.json", j.str() + "\n");

  std::ostringstream md;
  md.precision(3);
  md << "# Symmetry tracker against CSRT, KCF and CamShift\n\n"
     << "The ten simulated test videos of `nudge-exp-tracking-videos` (camera " << camera
     << "). CSRT and KCF (OpenCV " << CV_VERSION << " contrib `tracking`) and CamShift (hue–saturation "
        "histogram, 45 × 8 bins, of the target's true pixels in the first box; S < 40, V < 32 or V > 245 masked "
        "out) start from the target's true mask bounding box in frame 0; the symmetry tracker starts itself on the first "
        "motion. **Error** = distance from the box centre to the target's true axis (for the symmetry "
        "tracker: its rotated box's centre moved onto its own line). **Loss** = a scored frame where the "
        "tracker reports failure (CSRT/KCF `update` false, CamShift window collapsed, symmetry tracker not "
        "`Tracking`) or is more than "
     << kLossPx << " px off. Scored: from three frames after the target first moves to the end. "
        "**fps** = updates per second of tracker time only (no rendering), one thread.\n\n"
     << "Machine: " << machine_description() << ", " << today() << ".\n\n"
     << "| tracker | mean error px | median error px | losses / scored frames | fps |\n|---|---|---|---|---|\n";
  for (const std::string& name : kTrackers) {
    const Score& s = total[name];
    md << "| " << name << " | " << num(s.mean_error()) << " | " << num(s.errors.empty() ? NAN : median(s.errors))
       << " | " << s.losses << " / " << s.scored << " | " << num(s.fps()) << " |\n";
  }
  md << "\nPer video (mean error px / losses):\n\n| video |";
  for (const auto& name : kTrackers) md << " " << name << " |";
  md << "\n|---|---|---|---|---|\n";
  for (const auto& v : videos) {
    md << "| " << v.name << " |";
    for (const auto& name : kTrackers) {
      const Score& s = v.by_tracker.at(name);
      md << " " << num(s.mean_error()) << " / " << s.losses << " |";
    }
    md << "\n";
  }
  md << "\n![errors](tracker_comparison_errors.png)\n";
  write_result("tracker_comparison.md", md.str());

  const cv::Scalar colours[] = {{0, 0, 220}, {200, 80, 0}, {0, 160, 0}, {0, 140, 230}};
  std::vector<cv::Mat> tiles;
  for (const auto& v : videos) {
    std::vector<Series> series;
    for (size_t i = 0; i < kTrackers.size(); ++i) {
      const Score& s = v.by_tracker.at(kTrackers[i]);
      std::vector<double> clipped = s.error;
      for (double& e : clipped) e = std::min(e, 100.0);
      series.push_back(Series{kTrackers[i], s.frame, clipped, colours[i], false});
    }
    tiles.push_back(plot(series, v.name + " (clipped at 100 px)", "frame", "distance to true axis (px)", {640, 300}));
  }
  write_png("tracker_comparison_errors.png", tile(tiles, 2));
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 0, camera = 0;
  std::string only;
  Flags flags("nudge-exp-tracker-comparison",
              "The symmetry tracker against CSRT, KCF and CamShift on the simulated test videos.");
  flags.add_int("frames", &frames, "shorten every video to this many frames (0 = full length)");
  flags.add_int("camera", &camera, "camera of the stereo rig (0 left, 1 right)");
  flags.add_string("only", &only, "run only the video of this name (results are not written)");
  try {
    if (!flags.parse(argc, argv)) return 0;
    if (camera < 0 || camera > 1) throw FlagError("--camera: must be 0 or 1");
    if (frames < 0) throw FlagError("--frames: must be >= 0");
    std::vector<VideoScores> videos;
    for (const Scenario& sc : tracking_scenarios()) {
      if (!only.empty() && sc.name != only) continue;
      videos.push_back(run_video(sc, camera, frames));
    }
    if (videos.empty()) throw FlagError("--only: no video named '" + only + "'");
    if (only.empty()) write_results(videos, camera);
  } catch (const std::exception& e) {
    std::cerr << "nudge-exp-tracker-comparison: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
