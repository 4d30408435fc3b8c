#include "nudge/supervisor/line_search.hpp"

#include <algorithm>
#include <cmath>

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

}  // namespace

std::optional<symmetry::Line> find_line_near(const cv::Mat& image, const symmetry::Line& predicted,
                                             const LineSearchParams& params) {
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
  const symmetry::Result result = detector.detect(image);
  std::optional<symmetry::Line> best;
  bool best_reaches = false;
  double best_offset = params.window_px;
  for (const symmetry::Line& line : result.lines) {
    // In the form nearer the prediction: (R, theta) equals (-R, theta +- 180 deg).
    const double offset = std::abs(symmetry::line_difference(line, predicted).r);
    if (offset > params.window_px) continue;
    const bool reaches = reaches_foot(line, predicted, params.foot_slack);
    if (!best || (reaches && !best_reaches) || (reaches == best_reaches && offset <= best_offset)) {
      best_offset = offset;
      best_reaches = reaches;
      best = line;
    }
  }
  return best;
}

}  // namespace nudge::supervisor
