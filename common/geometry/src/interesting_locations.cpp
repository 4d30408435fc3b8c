#include "nudge/geometry/interesting_locations.hpp"
#include "nudge/geometry/upright.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

namespace nudge::geometry {

bool is_finite(const symmetry::Line& l) {
  return std::isfinite(l.r) && std::isfinite(l.theta) && std::isfinite(l.end1.x) && std::isfinite(l.end1.y) &&
         std::isfinite(l.end2.x) && std::isfinite(l.end2.y) && std::isfinite(l.seg1.x) && std::isfinite(l.seg1.y) &&
         std::isfinite(l.seg2.x) && std::isfinite(l.seg2.y);
}

namespace {

std::string pairing_name(int left, int right) {
  return "left " + std::to_string(left) + " x right " + std::to_string(right);
}

int lines_used(size_t available, int max_lines) {
  const int n = static_cast<int>(available);
  return max_lines > 0 && max_lines < n ? max_lines : n;
}

// One pairing: the axis, and its table hit when there is a table. Fails with the first reason.
Outcome<PairedAxis> pair_lines(const StereoRig& rig, const symmetry::Line& left, const symmetry::Line& right,
                               const Plane* table, const AxisFilter& filter, const TriangulationParams& params) {
  using Result = Outcome<PairedAxis>;
  if (!is_finite(left) || !is_finite(right))
    return Result::failure(std::string(is_finite(left) ? "right" : "left") + " line has non-finite values");
  const auto axis = triangulate_axis(rig, left, right, params);
  if (!axis) return Result::failure(axis.reason());
  PairedAxis paired;
  paired.axis = *axis;
  if (table) {
    const auto hit = check_axis(*axis, *table, filter);
    if (!hit) return Result::failure(hit.reason());
    paired.hit = *hit;
  }
  return Result::success(paired);
}

}  // namespace

PairingResult triangulate_pairings(const StereoRig& rig, const std::vector<symmetry::Line>& left,
                                   const std::vector<symmetry::Line>& right, const Plane* table,
                                   const AxisFilter& filter, const TriangulationParams& params, int max_lines) {
  PairingResult result;
  const int num_left = lines_used(left.size(), max_lines), num_right = lines_used(right.size(), max_lines);
  for (int i = 0; i < num_left; ++i) {
    for (int j = 0; j < num_right; ++j) {
      ++result.pairings;
      auto paired = pair_lines(rig, left[i], right[j], table, filter, params);
      if (!paired) {
        result.rejections.push_back(pairing_name(i, j) + ": " + paired.reason());
        continue;
      }
      PairedAxis axis = *paired;
      axis.left_index = i;
      axis.right_index = j;
      result.axes.push_back(axis);
    }
  }
  return result;
}

// ---------------------------------------------------------------------------------------------
// Table frame

TableFrame::TableFrame(const Plane& table, const std::optional<Eigen::Vector3d>& origin_hint) {
  const PlaneFrame plane(table);
  origin_ = origin_hint ? Eigen::Vector3d(*origin_hint - table.signed_distance(*origin_hint) * table.normal)
                        : plane.origin;
  axes_.row(0) = plane.x_axis.transpose();
  axes_.row(1) = plane.y_axis.transpose();
  axes_.row(2) = table.normal.transpose();
}

Eigen::Vector3d TableFrame::to_table(const Eigen::Vector3d& p) const { return axes_ * (p - origin_); }
Eigen::Vector3d TableFrame::to_camera(const Eigen::Vector3d& q) const { return axes_.transpose() * q + origin_; }

// ---------------------------------------------------------------------------------------------
// Interesting locations

void validate(const LocationParams& p) {
  if (p.frames < 1) throw std::invalid_argument("location parameter frames must be >= 1");
  if (p.lines_per_image < 1) throw std::invalid_argument("location parameter lines_per_image must be >= 1");
  if (!(p.max_tilt_deg >= 0 && p.max_tilt_deg <= 90))
    throw std::invalid_argument("location parameter max_tilt_deg must be in [0, 90]");
  if (!(p.max_range_m > 0)) throw std::invalid_argument("location parameter max_range_m must be > 0");
  if (!(p.ring_inner_m >= 0 && p.ring_outer_m > p.ring_inner_m))
    throw std::invalid_argument("location parameters need 0 <= ring_inner_m < ring_outer_m");
  if (!(p.qt.radius > 0) || !(p.qt.min_fraction >= 0 && p.qt.min_fraction <= 1))
    throw std::invalid_argument("location QT parameters need radius > 0 and min_fraction in [0, 1]");
  if (!(p.min_height_overlap >= 0 && p.min_height_overlap <= 1))
    throw std::invalid_argument("location parameter min_height_overlap must be in [0, 1]");
  if (!(p.max_foot_height_m > 0)) throw std::invalid_argument("location parameter max_foot_height_m must be > 0");
  if (!(p.explored_line_px > 0)) throw std::invalid_argument("location parameter explored_line_px must be > 0");
  if (!(p.column_line_px > 0)) throw std::invalid_argument("location parameter column_line_px must be > 0");
  if (!(p.min_axis_colour_agreement >= 0 && p.min_axis_colour_agreement <= 1))
    throw std::invalid_argument("location parameter min_axis_colour_agreement must be in [0, 1]");
  if (!(p.appearance_waived_at_overlap >= 0))
    throw std::invalid_argument("location parameter appearance_waived_at_overlap must be >= 0 (above 1: never waived)");
  if (!(p.appearance_min_top_m > 0 && p.appearance_max_top_m >= p.appearance_min_top_m))
    throw std::invalid_argument("location parameters need 0 < appearance_min_top_m <= appearance_max_top_m");
  validate(p.appearance);
  if (!(p.max_line_tilt_deg >= 0 && p.max_line_tilt_deg <= 90))
    throw std::invalid_argument("location parameter max_line_tilt_deg must be in [0, 90]");
  for (const Eigen::Vector3d& place : p.explored)
    if (!place.allFinite()) throw std::invalid_argument("location parameter explored holds a non-finite place");
}

bool is_image_of_upright_axis(const StereoRig& rig, Side side, const Plane& table, const symmetry::Line& line,
                              const Eigen::Vector3d& foot, double tolerance_px) {
  const Camera& camera = side == Side::Left ? rig.left : rig.right;
  const Eigen::Vector2d centre((camera.width - 1) / 2.0, (camera.height - 1) / 2.0);
  const Eigen::Vector2d normal(std::cos(line.theta), std::sin(line.theta));
  for (const double height : {0.0, 0.1}) {
    Eigen::Vector3d point = foot + height * table.normal.normalized() * (table.normal.dot(-foot) > 0 ? 1 : -1);
    if (side == Side::Left) point = rig.R.transpose() * (point - rig.T);  // x_right = R x_left + T
    if (!(point.z() > 0)) return false;
    const Eigen::Vector2d pixel = camera.project(point);
    if (std::abs((pixel - centre).dot(normal) - line.r) > tolerance_px) return false;
  }
  return true;
}

namespace {

// Parameter along the axis (unit direction `u` through `p0`) of the point nearest the ray o + t d.
std::optional<double> nearest_on_axis(const Eigen::Vector3d& p0, const Eigen::Vector3d& u, const Eigen::Vector3d& o,
                                      const Eigen::Vector3d& d) {
  const Eigen::Vector3d w = p0 - o;
  const double b = u.dot(d), c = d.dot(d), dd = u.dot(w), e = d.dot(w);
  const double denominator = c - b * b;  // |u| = 1
  if (denominator < 1e-12 * c) return std::nullopt;  // the ray runs along the axis
  return (b * e - c * dd) / denominator;
}

}  // namespace

Outcome<HeightRange> support_heights(const StereoRig& rig, Side side, const symmetry::Line& line, const Segment3& axis,
                                     const TableHit& hit, const Plane& table) {
  const Camera& camera = side == Side::Left ? rig.left : rig.right;
  Eigen::Vector3d up = axis.direction();
  if (up.dot(table.normal) < 0) up = -up;
  double h[2];
  const cv::Point2d ends[2] = {line.seg1, line.seg2};
  for (int i = 0; i < 2; ++i) {
    const auto n = camera.normalise(Eigen::Vector2d(ends[i].x, ends[i].y));
    if (!n) return Outcome<HeightRange>::failure("support end " + std::to_string(i + 1) + ": " + n.reason());
    Eigen::Vector3d origin = Eigen::Vector3d::Zero(), direction(n->x(), n->y(), 1.0);
    if (side == Side::Left) {
      origin = rig.left_centre();
      direction = rig.R * direction;
    }
    const auto t = nearest_on_axis(hit.point, up, origin, direction);
    if (!t) return Outcome<HeightRange>::failure("a support ray runs along the axis");
    h[i] = *t;
  }
  return Outcome<HeightRange>::success({std::min(h[0], h[1]), std::max(h[0], h[1])});
}

double height_overlap(const HeightRange& a, const HeightRange& b) {
  const double overlap = std::min(a.high, b.high) - std::max(a.low, b.low);
  const double span = std::max(a.high, b.high) - std::min(a.low, b.low);
  return span > 0 ? std::max(0.0, overlap) / span : 0.0;
}

namespace {

// A pairing's two support height ranges: those it carries, else computed now (nothing when either
// line's is not found).
std::optional<std::pair<HeightRange, HeightRange>> pairing_support(const StereoRig& rig, const std::vector<symmetry::Line>& left,
                                                                   const std::vector<symmetry::Line>& right, const PairedAxis& a,
                                                                   const Plane& table) {
  if (a.support) return a.support;
  if (!a.hit) return std::nullopt;
  const auto l = support_heights(rig, Side::Left, left[a.left_index], a.axis, *a.hit, table);
  const auto r = support_heights(rig, Side::Right, right[a.right_index], a.axis, *a.hit, table);
  if (!l || !r) return std::nullopt;
  return std::make_pair(*l, *r);
}

}  // namespace

PairingResult with_support_heights(const StereoRig& rig, const std::vector<symmetry::Line>& left,
                                   const std::vector<symmetry::Line>& right, PairingResult result, const Plane& table) {
  for (PairedAxis& a : result.axes) a.support = pairing_support(rig, left, right, a, table);
  return result;
}

std::vector<PairedAxis> consistent_pairings(const StereoRig& rig, const std::vector<symmetry::Line>& left,
                                            const std::vector<symmetry::Line>& right, const PairingResult& result,
                                            const Plane& table, const LocationParams& params) {
  struct Scored {
    double overlap;
    size_t index;
  };
  std::vector<Scored> scored;
  for (size_t i = 0; i < result.axes.size(); ++i) {
    const PairedAxis& a = result.axes[i];
    const auto support = pairing_support(rig, left, right, a, table);
    if (!support) continue;
    const auto& [l, r] = *support;
    const double share = height_overlap(l, r);
    const bool on_table = std::fabs(std::min(l.low, r.low)) <= params.max_foot_height_m;
    if (share >= params.min_height_overlap && on_table) scored.push_back({share, i});
  }
  std::stable_sort(scored.begin(), scored.end(), [](const Scored& a, const Scored& b) { return a.overlap > b.overlap; });
  std::vector<bool> left_used(left.size(), false), right_used(right.size(), false);
  std::vector<PairedAxis> out;
  for (const Scored& s : scored) {
    const PairedAxis& a = result.axes[s.index];
    if (left_used[a.left_index] || right_used[a.right_index]) continue;
    left_used[a.left_index] = right_used[a.right_index] = true;
    out.push_back(a);
  }
  return out;
}

LocationFinder::LocationFinder(const StereoRig& rig, const Plane& table, const std::optional<Eigen::Vector3d>& arm_base,
                               LocationParams params, TriangulationParams triangulation)
    : rig_(rig), table_(table), params_(params), triangulation_(triangulation), plane_frame_(table) {
  validate(params_);
  filter_.max_tilt_deg = params_.max_tilt_deg;
  filter_.max_range_m = params_.max_range_m;
  filter_.ring_inner_m = params_.ring_inner_m;
  filter_.ring_outer_m = params_.ring_outer_m;
  // The ring lies on the table around the base's foot, whatever the base's height.
  if (arm_base) filter_.ring_centre = TableFrame(table, arm_base).origin();
}

std::vector<symmetry::Line> LocationFinder::survey_lines(Side side, const std::vector<symmetry::Line>& lines) const {
  if (params_.explored.empty() && params_.max_line_tilt_deg <= 0) return lines;
  std::vector<symmetry::Line> kept;
  for (const symmetry::Line& line : lines) {
    if (std::any_of(params_.explored.begin(), params_.explored.end(), [&](const Eigen::Vector3d& place) {
          return is_image_of_upright_axis(rig_, side, table_, line, place, params_.explored_line_px);
        }))
      continue;
    if (params_.max_line_tilt_deg > 0) {
      const Outcome<double> tilt = upright_tilt_deg(rig_, side, table_, line);
      if (tilt && *tilt > params_.max_line_tilt_deg) continue;
    }
    kept.push_back(line);
  }
  return kept;
}

std::vector<symmetry::Line> first_lines_column_uncounted(const StereoRig& rig, Side side, const Plane& table,
                                                         const std::vector<symmetry::Line>& lines, int count,
                                                         const Eigen::Vector3d& column_foot, double column_px) {
  std::vector<symmetry::Line> first;
  int counted = 0;
  for (const symmetry::Line& line : lines) {
    if (counted >= count) break;
    first.push_back(line);
    counted += !is_image_of_upright_axis(rig, side, table, line, column_foot, column_px);
  }
  return first;
}

std::vector<symmetry::Line> LocationFinder::paired_lines(Side side, const std::vector<symmetry::Line>& lines) const {
  // The ring's centre is the arm base's foot, where its column stands.
  const std::optional<Eigen::Vector3d>& column_foot = filter_.ring_centre;
  const int count = params_.lines_per_image;
  if (!column_foot || params_.column_lines == LocationParams::ColumnLines::Counted)
    return {lines.begin(), lines.begin() + std::min<std::ptrdiff_t>(count, static_cast<std::ptrdiff_t>(lines.size()))};
  if (params_.column_lines == LocationParams::ColumnLines::Uncounted)
    return first_lines_column_uncounted(rig_, side, table_, lines, count, *column_foot, params_.column_line_px);
  std::vector<symmetry::Line> paired;  // Dropped
  for (const symmetry::Line& line : lines) {
    if (static_cast<int>(paired.size()) >= count) break;
    if (!is_image_of_upright_axis(rig_, side, table_, line, *column_foot, params_.column_line_px)) paired.push_back(line);
  }
  return paired;
}

LocationParams::ColumnLines parse_column_lines(const std::string& text) {
  if (text == "counted") return LocationParams::ColumnLines::Counted;
  if (text == "dropped") return LocationParams::ColumnLines::Dropped;
  if (text == "uncounted") return LocationParams::ColumnLines::Uncounted;
  throw std::invalid_argument("column lines: '" + text + "' is not one of counted, dropped, uncounted");
}

PairingResult appearance_consistent(const StereoRig& rig, const std::vector<symmetry::Line>& left,
                                    const std::vector<symmetry::Line>& right, const PairingResult& result,
                                    const Plane& table, const cv::Mat& left_image, const cv::Mat& right_image,
                                    const LocationParams& params) {
  if (params.min_axis_colour_agreement <= 0) return result;
  PairingResult kept = result;
  kept.axes.clear();
  for (const PairedAxis& a : result.axes) {
    if (!a.hit) continue;
    // Up to the lower support top: above an object's top both cameras see what stands behind it.
    double top = params.appearance_max_top_m;
    if (const auto support = pairing_support(rig, left, right, a, table)) {
      const auto& [l, r] = *support;
      if (height_overlap(l, r) >= params.appearance_waived_at_overlap) {
        kept.axes.push_back(a);
        continue;
      }
      top = std::min(l.high, r.high);
    }
    top = std::clamp(top, params.appearance_min_top_m, params.appearance_max_top_m);
    const Outcome<double> agreement =
        axis_colour_agreement(rig, left_image, right_image, a.axis, a.hit->point, table, top, params.appearance);
    if (agreement && *agreement >= params.min_axis_colour_agreement) {
      kept.axes.push_back(a);
      continue;
    }
    kept.rejections.push_back(pairing_name(a.left_index, a.right_index) + ": " +
                              (agreement ? "the two images agree along the axis at " + std::to_string(*agreement) +
                                               " of its heights (min " + std::to_string(params.min_axis_colour_agreement) + ")"
                                         : agreement.reason()));
  }
  return kept;
}

std::vector<PairedAxis> LocationFinder::frame_axes(const std::vector<symmetry::Line>& all_left,
                                                   const std::vector<symmetry::Line>& all_right,
                                                   const cv::Mat& left_image, const cv::Mat& right_image) const {
  const bool appearance = params_.min_axis_colour_agreement > 0;
  if (appearance && (left_image.empty() || right_image.empty()))
    throw std::invalid_argument("location finder: min_axis_colour_agreement needs the frame's two images");
  const std::vector<symmetry::Line> left = paired_lines(Side::Left, survey_lines(Side::Left, all_left));
  const std::vector<symmetry::Line> right = paired_lines(Side::Right, survey_lines(Side::Right, all_right));
  PairingResult result = triangulate_pairings(rig_, left, right, &table_, filter_, triangulation_, 0);  // 0: all of them
  if (appearance && params_.stereo_check) result = with_support_heights(rig_, left, right, std::move(result), table_);  // once for both
  if (appearance) result = appearance_consistent(rig_, left, right, result, table_, left_image, right_image, params_);
  return params_.stereo_check ? consistent_pairings(rig_, left, right, result, table_, params_) : result.axes;
}

int LocationFinder::add_frame(const std::vector<symmetry::Line>& all_left, const std::vector<symmetry::Line>& all_right,
                              const cv::Mat& left_image, const cv::Mat& right_image) {
  const std::vector<PairedAxis> axes = frame_axes(all_left, all_right, left_image, right_image);
  for (const PairedAxis& axis : axes) points_.push_back(axis.hit->point);
  ++frames_;
  return static_cast<int>(axes.size());
}

std::vector<Location> LocationFinder::locations() const {
  std::vector<Eigen::Vector2d> on_table;
  on_table.reserve(points_.size());
  for (const auto& p : points_) on_table.push_back(plane_frame_.to_plane(p));
  std::vector<Location> out;
  for (const Cluster& c : qt_cluster(on_table, params_.qt))
    out.push_back({plane_frame_.to_space(c.centroid), c.size()});
  return out;
}

void LocationFinder::reset() {
  frames_ = 0;
  points_.clear();
}

}  // namespace nudge::geometry
