#include "nudge/symmetry/line.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace nudge::symmetry {

void border_endpoints(double r, double theta, int width, int height, cv::Point2d* p1, cv::Point2d* p2) {
  const double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
  const cv::Point2d pivot(r * std::cos(theta) + cx, r * std::sin(theta) + cy);
  const cv::Point2d dir(-std::sin(theta), std::cos(theta));
  // Liang-Barsky clip of the infinite line against [0, w-1] x [0, h-1].
  double t0 = -1e12, t1 = 1e12;
  auto clip = [&](double p, double q) {  // p t <= q
    if (std::fabs(p) < 1e-12) return q >= 0;
    const double t = q / p;
    if (p < 0) t0 = std::max(t0, t);
    else t1 = std::min(t1, t);
    return true;
  };
  const bool ok = clip(-dir.x, pivot.x) && clip(dir.x, (width - 1) - pivot.x) && clip(-dir.y, pivot.y) &&
                  clip(dir.y, (height - 1) - pivot.y) && t0 <= t1;
  if (!ok) {  // the line misses the image: report the pivot twice
    *p1 = *p2 = pivot;
    return;
  }
  *p1 = pivot + t0 * dir;
  *p2 = pivot + t1 * dir;
}

LineDifference line_difference(double r, double theta, double reference_r, double reference_theta) {
  if (!std::isfinite(theta) || !std::isfinite(reference_theta)) return {r - reference_r, theta - reference_theta};
  // Half-turns that bring the line's theta within (-90, 90] deg of the reference's; each one
  // turns the normal around, so R changes sign.
  const double half_turns = std::ceil((theta - reference_theta) / M_PI - 0.5);
  const double d_theta = theta - reference_theta - half_turns * M_PI;
  const bool odd = std::fmod(std::fabs(half_turns), 2.0) == 1.0;
  return {(odd ? -r : r) - reference_r, d_theta};
}

Line line_from_region(const Line& line, const cv::Rect& region, const cv::Size& whole) {
  Line out = line;
  const cv::Point2d offset(region.x, region.y);
  const cv::Point2d region_centre((region.width - 1) / 2.0, (region.height - 1) / 2.0);
  const cv::Point2d whole_centre((whole.width - 1) / 2.0, (whole.height - 1) / 2.0);
  const cv::Point2d normal(std::cos(line.theta), std::sin(line.theta));
  out.r = line.r + normal.dot(offset + region_centre - whole_centre);
  out.seg1 = line.seg1 + offset;
  out.seg2 = line.seg2 + offset;
  border_endpoints(out.r, out.theta, whole.width, whole.height, &out.end1, &out.end2);
  return out;
}

namespace {

// The support segment's ends, or the line's border points when the support is a point.
std::pair<cv::Point2d, cv::Point2d> span_of(const Line& line) {
  if (cv::norm(line.seg2 - line.seg1) >= 1) return {line.seg1, line.seg2};
  return {line.end1, line.end2};
}

// Whether `line` lies within `min_px` of `taken` where their spans overlap along `taken`: both
// ends of the overlapping stretch of `line` within min_px of `taken`'s line.
bool same_place(const Line& line, const Line& taken, double min_px) {
  const auto [a1, a2] = span_of(taken);
  const cv::Point2d along = a2 - a1;
  const double length = cv::norm(along);
  if (length < 1e-9) return false;
  const cv::Point2d unit = along / length;
  const auto [b1, b2] = span_of(line);
  // Parameters of line's ends along taken's span, and their signed distances across it.
  const double t1 = (b1 - a1).dot(unit), t2 = (b2 - a1).dot(unit);
  const double d1 = unit.x * (b1 - a1).y - unit.y * (b1 - a1).x;
  const double d2 = unit.x * (b2 - a1).y - unit.y * (b2 - a1).x;
  const double lo = std::max(0.0, std::min(t1, t2)), hi = std::min(length, std::max(t1, t2));
  if (hi < lo) return false;  // one above the other in the image: two places
  const auto across_at = [&](double t) { return std::abs(t2 == t1 ? d1 : d1 + (d2 - d1) * (t - t1) / (t2 - t1)); };
  return across_at(lo) < min_px && across_at(hi) < min_px;
}

}  // namespace

std::vector<Line> one_line_per_place_first(const std::vector<Line>& lines, double min_px) {
  if (!std::isfinite(min_px)) throw std::invalid_argument("one line per place: the distance must be finite");
  if (min_px <= 0) return lines;
  std::vector<Line> first, waiting;
  for (const Line& line : lines) {
    const bool taken = std::any_of(first.begin(), first.end(), [&](const Line& t) { return same_place(line, t, min_px); });
    (taken ? waiting : first).push_back(line);
  }
  first.insert(first.end(), waiting.begin(), waiting.end());
  return first;
}

}  // namespace nudge::symmetry
