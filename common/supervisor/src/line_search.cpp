#include "nudge/supervisor/line_search.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/core.hpp>

#include "nudge/segmentation/motion.hpp"
#include "nudge/supervisor/scene.hpp"
#include "nudge/symmetry/line.hpp"

namespace nudge::supervisor {
namespace {

// Whether `line`'s support reaches down to the predicted axis' foot (predicted.seg1; seg2 its top):
// its end furthest along the axis from the top is at most `slack` of the axis' length short of the
// foot. True for a prediction without a span.
bool reaches_foot(const symmetry::Line& line, const symmetry::Line& predicted, double slack) {
  const cv::Point2d top_to_foot = predicted.seg1 - predicted.seg2;
  const double length = cv::norm(top_to_foot);
  if (length < 1) return true;
  const cv::Point2d down = top_to_foot / length;
  const double reach = std::max((line.seg1 - predicted.seg2).dot(down), (line.seg2 - predicted.seg2).dot(down));
  return reach >= (1 - slack) * length;
}

double changed_share_of(const cv::Mat& change, const symmetry::Line& line, double half_width_px, int threshold) {
  cv::Point2d from = line.seg1, to = line.seg2;
  if (cv::norm(to - from) < 1) symmetry::border_endpoints(line.r, line.theta, change.cols, change.rows, &from, &to);
  const double length = cv::norm(to - from);
  if (length < 1) return 0;
  const cv::Point2d along = (to - from) / length, across(-along.y, along.x);
  int samples = 0, changed = 0;
  for (double t = 0; t <= length; t += 1)
    for (double u = -half_width_px; u <= half_width_px; u += 1) {
      const cv::Point p(cvRound(from.x + t * along.x + u * across.x), cvRound(from.y + t * along.y + u * across.y));
      if (p.x < 0 || p.y < 0 || p.x >= change.cols || p.y >= change.rows) continue;
      ++samples;
      changed += change.at<uint8_t>(p) > threshold;
    }
  return samples ? static_cast<double>(changed) / samples : 0;
}

}  // namespace

double changed_share(const cv::Mat& earlier, const cv::Mat& later, const symmetry::Line& line, double half_width_px,
                     int threshold) {
  if (earlier.empty() || earlier.size() != later.size() || earlier.type() != later.type()) return 0;
  return changed_share_of(segmentation::largest_channel_change(earlier, later), line, half_width_px, threshold);
}

cv::Rect search_region(const cv::Size& size, const symmetry::Line& predicted, const LineSearchParams& params) {
  const cv::Rect whole(0, 0, size.width, size.height);
  const cv::Point2d axis = predicted.seg2 - predicted.seg1;
  const double length = cv::norm(axis);
  if (length < 1) return whole;
  const cv::Point2d along = axis / length;
  const cv::Point2d across(-along.y, along.x);
  const double scale = size.width / 640.0;
  const double half_pair = 0.5 * params.max_pair_width_px * scale;
  const double window = params.window_deg * M_PI / 180;
  // A line within the windows passes within window_px + 2 sin(window / 2) |p - centre| of a point p
  // of the predicted line (the normals differ by at most the angle window); its pairs reach
  // half_pair across it and half_pair sin(window) along the predicted axis.
  const cv::Point2d centre((size.width - 1) / 2.0, (size.height - 1) / 2.0);
  const double farthest = std::max(cv::norm(predicted.seg1 - centre), cv::norm(predicted.seg2 - centre)) + params.window_px;
  const double half_width = params.window_px + 2 * std::sin(window / 2) * farthest + half_pair + 2;  // 2: Sobel's reach
  const double half_length = 0.5 * length + params.window_px + half_pair * std::sin(window) + 2;
  const cv::Point2d middle = 0.5 * (predicted.seg1 + predicted.seg2);
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (int a : {-1, 1})
    for (int b : {-1, 1}) {
      const cv::Point2d corner = middle + a * half_length * along + b * half_width * across;
      x0 = std::min(x0, corner.x), y0 = std::min(y0, corner.y), x1 = std::max(x1, corner.x), y1 = std::max(y1, corner.y);
    }
  const cv::Rect band(cv::Point(static_cast<int>(std::floor(x0)), static_cast<int>(std::floor(y0))),
                      cv::Point(static_cast<int>(std::ceil(x1)) + 1, static_cast<int>(std::ceil(y1)) + 1));
  return band & whole;
}

std::optional<symmetry::Line> find_line_near(const cv::Mat& image, const symmetry::Line& predicted,
                                             const LineSearchParams& params,
                                             const std::vector<symmetry::Line>& not_objects,
                                             const cv::Mat& earlier) {
  if (image.empty()) return std::nullopt;
  const double scale = image.cols / 640.0;  // the detector's thesis distances are for 640x480
  symmetry::Params p;
  p.dmin = params.min_pair_width_px * scale;
  p.dmax = params.max_pair_width_px * scale;
  const double theta_deg = predicted.theta * 180 / M_PI;
  p.theta_min_deg = theta_deg - params.window_deg;
  p.theta_max_deg = theta_deg + params.window_deg;
  // The window may cross +-90 deg: the detector takes a wrapped range as theta_min > theta_max.
  if (p.theta_max_deg > 90) p.theta_max_deg -= 180;
  if (p.theta_min_deg <= -90) p.theta_min_deg += 180;
  p.num_lines = params.lines;
  p.once_per_row = true;
  p.mirror_tolerance_deg = params.mirror_tolerance_deg;
  symmetry::EdgeParams edges;
  edges.gradients = params.mirror_tolerance_deg > 0;
  symmetry::Detector detector(p, edges);
  const cv::Rect region = params.crop_to_prediction ? search_region(image.size(), predicted, params)
                                                    : cv::Rect(0, 0, image.cols, image.rows);
  if (region.width < 2 || region.height < 2) return std::nullopt;  // the predicted axis lies outside the still
  const symmetry::Result result = detector.detect(image(region));
  const bool compare = !earlier.empty();
  if (compare && (earlier.size() != image.size() || earlier.type() != image.type()))
    throw std::invalid_argument("find_line_near: the earlier still differs from the still in size or type");
  cv::Mat change;  // made when a line first needs it (lines off the window or avoided need none)
  const auto changed_share_about = [&](const symmetry::Line& line) {
    if (change.empty()) change = segmentation::largest_channel_change(earlier, image);
    return changed_share_of(change, line, 0.5 * p.dmin, params.change_threshold);
  };
  // A not-an-object line the prediction itself lies on is not avoided: the object stands in line
  // with it in the image (its line and the column's are one), and the one line is the object's.
  const double not_object_angle = params.not_object_deg * M_PI / 180;
  std::vector<symmetry::Line> avoided;
  for (const symmetry::Line& other : not_objects)
    if (!lines_agree(predicted, other, not_object_angle, params.not_object_px)) avoided.push_back(other);
  std::optional<symmetry::Line> best;
  bool best_reaches = false;
  double best_offset = params.window_px;
  double best_votes = 0;
  for (const symmetry::Line& found : result.lines) {
    const symmetry::Line line = symmetry::line_from_region(found, region, image.size());
    // In the form nearer the prediction: (R, theta) equals (-R, theta +- 180 deg).
    const double offset = std::abs(symmetry::line_difference(line, predicted).r);
    if (offset > params.window_px) continue;
    if (std::any_of(avoided.begin(), avoided.end(), [&](const symmetry::Line& other) {
          return lines_agree(line, other, not_object_angle, params.not_object_px);
        }))
      continue;
    // Where nothing changed about the line since the earlier still, it stood there then.
    if (compare && changed_share_about(line) < params.min_changed_share)
      continue;
    const bool reaches = reaches_foot(line, predicted, params.foot_slack);
    const bool preferred = params.strongest ? line.votes > best_votes : offset <= best_offset;
    if (!best || (reaches && !best_reaches) || (reaches == best_reaches && preferred)) {
      best_votes = line.votes;
      best_offset = offset;
      best_reaches = reaches;
      best = line;
    }
  }
  return best;
}

symmetry::Line turned_about_foot(const symmetry::Line& predicted, double angle, const cv::Size& size) {
  const cv::Point2d span = predicted.seg2 - predicted.seg1;
  const bool has_span = cv::norm(span) >= 1;
  const double c = std::cos(angle), s = std::sin(angle);
  // The line's direction (-sin theta, cos theta) turns as its normal (cos theta, sin theta) does.
  const cv::Point2d direction = has_span ? span : cv::Point2d(-std::sin(predicted.theta), std::cos(predicted.theta));
  const cv::Point2d turned(c * direction.x - s * direction.y, s * direction.x + c * direction.y);
  symmetry::Line line = line_through(predicted.seg1, predicted.seg1 + turned, size);
  line.seg1 = predicted.seg1;
  line.seg2 = has_span ? predicted.seg1 + turned : predicted.seg1;
  return line;
}

std::optional<symmetry::Line> find_moved_line(const cv::Mat& after, const symmetry::Line& predicted_after,
                                              const symmetry::Line& predicted_before,
                                              const std::optional<symmetry::Line>& before_line,
                                              const LineSearchParams& params,
                                              const std::vector<symmetry::Line>& not_objects,
                                              const cv::Mat& earlier) {
  // Two detections, not one over +-window_deg filtered twice: the narrow one's `lines` peaks all
  // lie within +-lean_window_deg, where the wide one's strongest could all lie outside it (a
  // neighbour's lines, a label's stripes), leaving the object's line unexamined.
  if (before_line && params.lean_window_deg > 0) {
    const double lean = symmetry::line_difference(*before_line, predicted_before).theta;
    LineSearchParams narrow = params;
    narrow.window_deg = std::min(params.lean_window_deg, params.window_deg);
    if (auto line = find_line_near(after, turned_about_foot(predicted_after, lean, after.size()), narrow, not_objects, earlier))
      return line;
  }
  return find_line_near(after, predicted_after, params, not_objects, earlier);
}

}  // namespace nudge::supervisor
