// nudge-exp-clutter (issue 14): symmetry lines and CANDIDATES on busy tables.
//
// For every scene of the clutter family (common/sim/scenes/clutter/, nudge-clutter-scenes) it
// renders `--frames` noisy stereo pairs, detects each camera's lines as the symmetry service does
// in the supervisor's loop, and feeds the pairs to the triangulation service's LocationFinder as
// a survey does. Against the simulator's truth it counts, per camera, the objects whose projected
// axis is among the lines (within 3 px at the axis' middle and 2 deg), the phantom lines (further
// than 8 px or 5 deg from every object's axis: between objects, or in texture), and after
// clustering the candidates within 25 mm of an object's axis, the objects without one, and the
// phantom candidates. Two pipelines are measured in one run: the one before issue 14 and today's.
//   nudge-exp-clutter [--set eval|dev] [--frames 25] [--no-write]
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <tuple>
#include <sstream>

#include "nudge/flags.hpp"
#include "nudge/progress.hpp"
#include "nudge/timing.hpp"
#include "nudge/geometry/axis_appearance.hpp"
#include "nudge/geometry/interesting_locations.hpp"
#include "nudge/geometry/table_texture.hpp"
#include "nudge/geometry/upright.hpp"
#include "nudge/sim/world.hpp"
#include "nudge/symmetry/detector.hpp"
#include "nudge/symmetry/verify.hpp"
#include "report.hpp"

namespace fs = std::filesystem;
namespace geo = nudge::geometry;
namespace sim = nudge::sim;
namespace sym = nudge::symmetry;
using namespace nudge::experiments;

namespace {

constexpr double kLineDistancePx = 3, kLineAngleDeg = 2;        // "among the lines" (issue 14)
constexpr double kPhantomDistancePx = 8, kPhantomAngleDeg = 5;  // further from every axis: a phantom
constexpr double kCandidateRadiusM = 0.025;                     // a candidate this close is the object
constexpr int kMinVisiblePixels = 150;                          // fewer: the object is hidden

// What turns images into lines and lines into candidates.
struct Pipeline {
  std::string name;
  sym::Params params;
  sym::EdgeParams edge;
  sym::VerifyParams verify;
  bool verify_lines = false;
  double upright_max_deg = 0;  // > 0: only peaks that can be upright axes are verified
  bool upright_snap = false;    // the verified lines turned into images of upright axes
  // The table's own texture left out of the edges (geometry/table_texture.hpp; nudge-symmetry
  // --table-texture-calibration): --table-texture 1 adds it to every pipeline.
  bool table_texture = false;
  geo::LocationParams locations;
};

// The symmetry service as scripts/lib.sh and the supervisor's loop test run it, and the
// triangulation service's defaults with the supervisor's survey request (25 frames, 3 lines).
Pipeline before_issue14() {
  Pipeline p;
  p.name = "before";
  p.params.num_lines = 5;
  p.params.theta_min_deg = -25;
  p.params.theta_max_deg = 25;
  p.params.once_per_row = true;
  p.params.mirror_tolerance_deg = 15;
  p.edge.blur_sigma = 1.0;
  p.locations.frames = 25;
  p.locations.lines_per_image = 3;
  return p;
}

// Issue 14's pipeline (docs/clutter.md): every value below was chosen on the development family.
struct AfterOptions {
  double dmin = 8, dmax = 90, blur = 2.0, canny_low = 30, canny_high = 90;
  int candidates = 80, suppress = 3, keep = 12;  // first round: 20 peaks, 8 kept; suppression 4 until the fifth round
  bool verify = true;
  double appearance_weight = 1, band_weight = 0.5, min_appearance = 0, colour_tolerance = 90, band_gap = 8, verify_suppress = 4;
  double support_gap = 16;  // fifth round: bands joined across gaps up to this into the support (0: the band alone)
  int candidate_lines = 8;
  bool stereo_check = true, colour_edges = true;
  double min_overlap = 0.2, max_foot = 0.08;  // third round: 0.3 without the stereo appearance
  bool refine = false;
  double refine_max = 4;
  double upright = 2;  // second round: only peaks that can be upright axes are verified
  bool snap = false;
  double min_fraction = 0.05;  // fifth round (0.03 before)
  double min_agreement = 0.6;  // stereo appearance along the axis (0: off); fourth round 0.5, fifth 0.6
  double agreement_tolerance = 60;
  int agreement_window = 1;
  double agreement_waived = 0.85;  // fourth round 0.7
};

Pipeline after_issue14(const AfterOptions& o) {
  Pipeline p = before_issue14();
  p.name = "after";
  p.params.dmin = o.dmin;
  p.params.dmax = o.dmax;
  p.params.num_lines = o.candidates;
  p.params.suppress_r = o.suppress;
  p.params.suppress_theta = o.suppress;
  p.edge.blur_sigma = o.blur;
  p.edge.canny_low = o.canny_low;
  p.edge.canny_high = o.canny_high;
  p.edge.colour = o.colour_edges;
  p.verify_lines = o.verify;
  p.verify.keep = o.keep;
  p.verify.appearance_weight = o.appearance_weight;
  p.verify.band_weight = o.band_weight;
  p.verify.min_appearance = o.min_appearance;
  p.verify.colour_tolerance = o.colour_tolerance;
  p.verify.band_gap_px = o.band_gap;
  p.verify.support_gap_px = o.support_gap;
  p.verify.suppress_px = o.verify_suppress;
  p.verify.refine = o.refine;
  p.upright_max_deg = o.upright;
  p.upright_snap = o.snap;
  p.verify.refine_max_deg = o.refine_max;
  p.locations.lines_per_image = o.candidate_lines;
  p.locations.stereo_check = o.stereo_check;
  p.locations.min_height_overlap = o.min_overlap;
  p.locations.max_foot_height_m = o.max_foot;
  p.locations.qt.min_fraction = o.min_fraction;
  p.locations.min_axis_colour_agreement = o.min_agreement;
  p.locations.appearance.colour_tolerance = o.agreement_tolerance;
  p.locations.appearance.window_px = o.agreement_window;
  p.locations.appearance_waived_at_overlap = o.agreement_waived;
  return p;
}

struct CameraCount {
  int visible = 0, found = 0, lines = 0, phantoms = 0, images = 0;
};

// Where each object that is not in a camera's lines was lost (--diagnose; object-frames, both
// cameras): its axis among the verified lines (found), among the accumulator's peaks but dropped by
// the verification, a peak of the accumulator (suppression 1) ranked within the peaks taken but
// removed by the coarser suppression, ranked lower, or no peak of the accumulator at all.
struct LineLoss {
  int found = 0, verification = 0, suppressed = 0, rank_low = 0, below_ratio = 0, no_peak = 0;
};
// Per object: never in both cameras' lines in one frame; in both but no table intersect near it
// (stereo pairing, the stereo check, the upright / workspace filter); intersects but no cluster.
struct CandidateLoss {
  int candidate = 0, never_both = 0, no_intersect = 0, not_clustered = 0;
  int never_both_but_each = 0;  // of never_both: in each camera's lines, only never in the same frame
};
// What became of the pairing of an object's own left and right lines, per object-frame in both
// cameras' lines (--diagnose): one line ranked beyond the lines paired, the axis refused (tilt,
// range, workspace ring, triangulation), its table hit further than 25 mm from the object, the
// stereo check's height overlap or foot, another pairing taking one of its lines first, or an
// intersect near the object.
struct PairLoss {
  int ranked_beyond = 0, tilt = 0, range = 0, ring = 0, triangulation = 0, hit_far = 0, overlap = 0, foot = 0,
      taken = 0, near = 0;
  std::vector<double> hit_mm;  // the valid pairings' hit distance from the object
};

struct SceneResult {
  std::string name;
  int objects = 0;
  std::array<CameraCount, 2> cameras;
  LineLoss line_loss;
  CandidateLoss candidate_loss;
  PairLoss pair_loss;
  double pair_ms = 0;  // both cameras' detection and the pair's candidate intersects, summed over frames
  int candidates = 0, object_candidates = 0, duplicate_candidates = 0, objects_without = 0, phantom_candidates = 0;
  cv::Mat picture;
};

double angle_diff_deg(double a, double b) {
  double d = std::fmod(std::fabs(a - b), M_PI);
  if (d > M_PI / 2) d = M_PI - d;
  return d * 180 / M_PI;
}

// Distance from the middle of the true axis' image to the line, and the angle between them.
std::pair<double, double> line_error(const sym::Line& line, const sim::ImageLine& truth, int width, int height) {
  const Eigen::Vector2d middle = 0.5 * (truth.bottom + truth.top);
  const double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
  const double distance = std::fabs((middle.x() - cx) * std::cos(line.theta) + (middle.y() - cy) * std::sin(line.theta) - line.r);
  return {distance, angle_diff_deg(line.theta, truth.theta)};
}

geo::Plane table_in_right_camera(const sim::World& world) {
  const sim::CameraModel& right = world.camera(1);
  geo::Plane p;
  p.normal = right.R * Eigen::Vector3d::UnitZ();
  p.offset = -p.normal.dot(right.t);
  if (p.offset < 0) {
    p.normal = -p.normal;
    p.offset = -p.offset;
  }
  return p;
}

// The stages of one image's detection, kept for the diagnosis.
struct Detection {
  std::vector<sym::Line> peaks;  // the accumulator's peaks (before verification)
  std::vector<sym::Line> lines;  // what the pipeline returns
};

// Where an image was taken, for the upright check; with the table texture also the other
// camera's image of the moment and the warp through the table plane.
struct View {
  const geo::StereoRig* rig = nullptr;
  const geo::Plane* table = nullptr;
  geo::Side side = geo::Side::Left;
  const cv::Mat* other = nullptr;
  const geo::PlaneWarp* warp = nullptr;
};

Detection detect(sym::Detector& detector, const Pipeline& pipeline, const cv::Mat& image, const View& view) {
  if (!pipeline.verify_lines && !pipeline.table_texture) {
    std::vector<sym::Line> lines = detector.detect(image).lines;
    return {lines, lines};
  }
  sym::EdgeParams edge = pipeline.edge;
  edge.gradients = true;  // as Detector::detect with the mirror rule on
  sym::EdgeSet edges = sym::detect_edges(image, edge);
  if (pipeline.table_texture) sym::remove_edges(edges, geo::table_texture_mask(image, *view.other, *view.warp));
  const sym::Result result = detector.detect(edges);
  if (!pipeline.verify_lines) return {result.lines, result.lines};
  std::vector<sym::Line> peaks = result.lines;
  if (pipeline.upright_max_deg > 0)
    peaks = geo::upright_lines(*view.rig, view.side, *view.table, peaks, pipeline.upright_max_deg);
  std::vector<sym::Line> lines = sym::verify_lines(detector, edges, image, peaks, pipeline.verify);
  if (pipeline.upright_snap) lines = geo::upright_lines(*view.rig, view.side, *view.table, lines, 90, true);
  return {result.lines, lines};
}

bool matches(const sym::Line& line, const sim::ImageLine& truth, int width, int height) {
  const auto [d, a] = line_error(line, truth, width, height);
  return d <= kLineDistancePx && a <= kLineAngleDeg;
}

bool any_matches(const std::vector<sym::Line>& lines, const sim::ImageLine& truth, int width, int height) {
  for (const auto& l : lines)
    if (matches(l, truth, width, height)) return true;
  return false;
}

// --dump: features of every accumulator peak, one CSV row each, with what it is (the object it
// matches within 3 px / 2 deg, -1 near an object but not on it, -2 a phantom), to design scores.
struct PeakDump {
  std::ofstream* out = nullptr;
  std::string scene;
  int frame = 0, camera = 0;
};

// How far (deg) the plane through the camera centre and an image line is from containing the
// table's normal: an upright axis' image has 0 (up to the axis' tilt).
double upright_tilt_deg(const sim::CameraModel& camera, const sym::Line& line) {
  const Eigen::Vector2d a = camera.undistort({line.end1.x, line.end1.y}), b = camera.undistort({line.end2.x, line.end2.y});
  const Eigen::Vector3d m = Eigen::Vector3d(a.x(), a.y(), 1).cross(Eigen::Vector3d(b.x(), b.y(), 1)).normalized();
  const Eigen::Vector3d up = camera.R * Eigen::Vector3d::UnitZ();
  return std::asin(std::min(1.0, std::fabs(m.dot(up)))) * 180 / M_PI;
}

void dump_peaks(const sym::Detector& detector, const Pipeline& pipeline, const cv::Mat& image,
                const std::vector<sim::ImageLine>& truth, const std::vector<bool>& visible, const PeakDump& d,
                const sim::CameraModel& camera) {
  sym::EdgeParams edge = pipeline.edge;
  edge.gradients = true;
  const sym::EdgeSet edges = sym::detect_edges(image, edge);
  sym::Detector probe(detector.params(), pipeline.edge);
  const sym::Result result = probe.detect(edges);
  cv::Mat direction(image.size(), CV_16S, cv::Scalar(0));
  for (size_t i = 0; i < edges.points.size(); ++i) direction.at<int16_t>(edges.points[i]) = edges.direction[i];
  const cv::Point2d centre(0.5 * (image.cols - 1), 0.5 * (image.rows - 1));
  for (size_t k = 0; k < result.lines.size(); ++k) {
    const sym::Line& line = result.lines[k];
    const sym::LineEvidence e = sym::line_evidence(probe, edges, image, line, pipeline.verify);
    const auto pairs = probe.voting_pairs(edges, line);
    const cv::Point2d normal(std::cos(line.theta), std::sin(line.theta)), dir(-normal.y, normal.x);
    std::vector<std::pair<double, double>> along_width;
    int polarity = 0;
    for (const auto& p : pairs) {
      const cv::Point2d a(p.a), b(p.b);
      along_width.push_back({(0.5 * (a + b) - centre).dot(dir), cv::norm(b - a)});
      // Mirrored directions: a + b = 2 theta + 180 deg (mod 360), in 360/65536 units.
      const int16_t sum = static_cast<int16_t>(direction.at<int16_t>(p.a) + direction.at<int16_t>(p.b));
      const int16_t want = sym::direction_units(2 * line.theta + M_PI);
      polarity += std::abs(static_cast<int16_t>(sum - want)) <= 30 * 65536 / 360;
    }
    std::sort(along_width.begin(), along_width.end());
    // Largest band, its length and rows; width smoothness inside it.
    size_t best_start = 0, best_end = 0, start = 0;
    for (size_t i = 1; i <= along_width.size(); ++i) {
      if (i < along_width.size() && along_width[i].first - along_width[i - 1].first <= pipeline.verify.band_gap_px) continue;
      if (i - start > best_end - best_start) best_start = start, best_end = i;
      start = i;
    }
    double band_len = 0;
    int rows = 0, smooth = 0;
    if (best_end > best_start) {
      band_len = along_width[best_end - 1].first - along_width[best_start].first;
      double last_row = -1e9;
      for (size_t i = best_start; i < best_end; ++i) {
        if (along_width[i].first - last_row >= 0.9) ++rows, last_row = along_width[i].first;
        bool near = false;
        for (size_t j = i > best_start + 3 ? i - 3 : best_start; j < std::min(best_end, i + 4); ++j)
          if (j != i && std::fabs(along_width[j].second - along_width[i].second) <= 3) near = true;
        smooth += near;
      }
    }
    int label = -2;
    for (size_t i = 0; i < truth.size(); ++i) {
      if (!truth[i].valid) continue;
      const auto [dist, ang] = line_error(line, truth[i], image.cols, image.rows);
      if (visible[i] && dist <= kLineDistancePx && ang <= kLineAngleDeg) { label = static_cast<int>(i); break; }
      if (dist <= kPhantomDistancePx && ang <= kPhantomAngleDeg) label = -1;
    }
    *d.out << d.scene << "," << d.frame << "," << d.camera << "," << k << "," << line.votes << "," << e.pairs << ","
           << e.band_share << "," << e.appearance << "," << band_len << "," << rows << "," << smooth << "," << polarity
           << "," << line.r << "," << line.theta << "," << label << "," << upright_tilt_deg(camera, line) << "\n";
  }
}

// Where a visible object missing from `detection.lines` was lost (LineLoss).
void diagnose_line(const sym::Detector& detector, const Detection& detection, const sim::ImageLine& truth,
                   int width, int height, LineLoss* loss) {
  if (any_matches(detection.lines, truth, width, height)) return void(++loss->found);
  if (any_matches(detection.peaks, truth, width, height)) return void(++loss->verification);
  sym::Params fine = detector.params();
  fine.num_lines = 300;
  fine.suppress_r = fine.suppress_theta = 1;
  fine.min_peak_ratio = 0;
  const std::vector<sym::Line> all = sym::Detector(fine).find_peaks(detector.last_accumulator(), width, height);
  const double highest = all.empty() ? 0 : all.front().votes;
  for (size_t k = 0; k < all.size(); ++k) {
    if (!matches(all[k], truth, width, height)) continue;
    if (all[k].votes < detector.params().min_peak_ratio * highest) return void(++loss->below_ratio);
    if (static_cast<int>(k) < detector.params().num_lines) return void(++loss->suppressed);
    return void(++loss->rank_low);
  }
  ++loss->no_peak;
}

int first_match(const std::vector<sym::Line>& lines, const sim::ImageLine& truth, int width, int height) {
  for (size_t k = 0; k < lines.size(); ++k)
    if (matches(lines[k], truth, width, height)) return static_cast<int>(k);
  return -1;
}

// A point of the right camera's frame in the world's.
Eigen::Vector3d in_world(const sim::CameraModel& right, const Eigen::Vector3d& p) { return right.R.transpose() * (p - right.t); }

// PairLoss of one object-frame: `il`, `ir` index the object's lines in `left`, `right`; `axes` are
// the pairings the finder kept for the frame; `object_xy` the object's place (world frame).
void diagnose_pairing(const geo::StereoRig& rig, const geo::Plane& table, const geo::AxisFilter& filter,
                      const geo::LocationParams& params, const std::vector<sym::Line>& left,
                      const std::vector<sym::Line>& right, int il, int ir, const std::vector<geo::PairedAxis>& axes,
                      const sim::CameraModel& right_camera, const Eigen::Vector2d& object_xy, PairLoss* loss) {
  if (il >= params.lines_per_image || ir >= params.lines_per_image) return void(++loss->ranked_beyond);
  const geo::PairingResult one = geo::triangulate_pairings(rig, {left[il]}, {right[ir]}, &table, filter);
  if (one.axes.empty()) {
    // Which of the filter's tests refuses it: each applied alone to the unfiltered axis.
    geo::AxisFilter none;
    none.max_tilt_deg = 90;
    none.max_range_m = std::numeric_limits<double>::infinity();
    none.ring_centre.reset();
    const geo::PairingResult unfiltered = geo::triangulate_pairings(rig, {left[il]}, {right[ir]}, &table, none);
    if (unfiltered.axes.empty()) return void(++loss->triangulation);
    const geo::Segment3& axis = unfiltered.axes.front().axis;
    geo::AxisFilter tilt = none, range = none, ring = none;
    tilt.max_tilt_deg = filter.max_tilt_deg;
    range.max_range_m = filter.max_range_m;
    ring.ring_centre = filter.ring_centre;
    ring.ring_inner_m = filter.ring_inner_m;
    ring.ring_outer_m = filter.ring_outer_m;
    if (!geo::check_axis(axis, table, tilt)) return void(++loss->tilt);
    if (!geo::check_axis(axis, table, range)) return void(++loss->range);
    if (!geo::check_axis(axis, table, ring)) return void(++loss->ring);
    return void(++loss->triangulation);
  }
  const Eigen::Vector3d hit = in_world(right_camera, one.axes.front().hit->point);
  const double distance = (hit.head<2>() - object_xy).norm();
  loss->hit_mm.push_back(1000 * distance);
  if (distance > kCandidateRadiusM) return void(++loss->hit_far);
  if (params.stereo_check) {
    geo::LocationParams any_foot = params;
    any_foot.max_foot_height_m = 1e3;
    geo::PairingResult single = one;
    single.axes.front().left_index = il;
    single.axes.front().right_index = ir;
    if (geo::consistent_pairings(rig, left, right, single, table, any_foot).empty()) return void(++loss->overlap);
    if (geo::consistent_pairings(rig, left, right, single, table, params).empty()) return void(++loss->foot);
  }
  for (const geo::PairedAxis& a : axes)
    if (a.left_index == il && a.right_index == ir) return void(++loss->near);
  ++loss->taken;
}

void draw_frame(const cv::Mat& image, const std::vector<sym::Line>& lines, const std::vector<sim::ImageLine>& truth,
                const std::vector<Eigen::Vector2d>& candidates, const std::vector<bool>& candidate_is_object,
                cv::Mat* out) {
  cv::Mat canvas = image.clone();
  for (const auto& t : truth)
    if (t.valid) cv::line(canvas, cv::Point2d(t.bottom.x(), t.bottom.y()), cv::Point2d(t.top.x(), t.top.y()), {0, 255, 0}, 1);
  for (const auto& l : lines) cv::line(canvas, l.seg1, l.seg2, {0, 0, 255}, 2);
  for (size_t i = 0; i < candidates.size(); ++i) {
    const cv::Point c(cvRound(candidates[i].x()), cvRound(candidates[i].y()));
    const cv::Scalar colour = candidate_is_object[i] ? cv::Scalar(255, 255, 0) : cv::Scalar(255, 0, 255);
    cv::drawMarker(canvas, c, colour, cv::MARKER_TILTED_CROSS, 18, 3);
  }
  *out = canvas;
}

// --dump-pairings: every valid pairing of a frame's paired lines, one CSV row each, with its
// stereo-check numbers and what it is (to design the pairing rule).
void dump_pairings(const geo::StereoRig& rig, const geo::Plane& table, const geo::LocationFinder& finder,
                   const geo::LocationParams& params, const std::array<std::vector<sym::Line>, 2>& lines,
                   const std::array<std::vector<sim::ImageLine>, 2>& truth, const sim::World& world,
                   const sim::StereoImages& images, const std::string& scene, int frame, std::ofstream* out) {
  const sim::CameraModel& right = world.camera(1);
  const geo::PairingResult result = geo::triangulate_pairings(rig, lines[0], lines[1], &table, finder.axis_filter(),
                                                              {}, params.lines_per_image);
  auto object_of = [&](int c, const sym::Line& line) {
    for (int i = 0; i < world.num_objects(); ++i)
      if (truth[c][i].valid && matches(line, truth[c][i], images.colour[c].cols, images.colour[c].rows)) return i;
    return -1;
  };
  for (const geo::PairedAxis& a : result.axes) {
    const auto l = geo::support_heights(rig, geo::Side::Left, lines[0][a.left_index], a.axis, *a.hit, table);
    const auto r = geo::support_heights(rig, geo::Side::Right, lines[1][a.right_index], a.axis, *a.hit, table);
    if (!l || !r) continue;
    const Eigen::Vector3d hit = in_world(right, a.hit->point);
    int nearest = -1;
    double best = 1e9;
    for (int i = 0; i < world.num_objects(); ++i) {
      const double d = (hit.head<2>() - world.object(i).position.head<2>()).norm();
      if (d < best) best = d, nearest = i;
    }
    const auto tl = geo::upright_tilt_deg(rig, geo::Side::Left, table, lines[0][a.left_index]);
    const auto tr = geo::upright_tilt_deg(rig, geo::Side::Right, table, lines[1][a.right_index]);
    auto agreement = [&](double top, double tolerance) {
      geo::AxisAppearanceParams ap;
      ap.colour_tolerance = tolerance;
      const auto g = geo::axis_colour_agreement(rig, images.colour[0], images.colour[1], a.axis, a.hit->point, table,
                                                std::clamp(top, 0.04, 0.30), ap);
      return g ? *g : -1.0;
    };
    const double top = std::min(l->high, r->high);
    *out << agreement(top, 60) << "," << agreement(top, 30) << "," << agreement(0.08, 60) << ",";
    *out << scene << "," << frame << "," << a.left_index << "," << a.right_index << ","
         << object_of(0, lines[0][a.left_index]) << "," << object_of(1, lines[1][a.right_index]) << "," << nearest
         << "," << best * 1000 << "," << l->low << "," << l->high << "," << r->low << "," << r->high << ","
         << a.hit->tilt_deg << "," << (tl ? *tl : -1) << "," << (tr ? *tr : -1) << ","
         << lines[0][a.left_index].votes << "," << lines[1][a.right_index].votes << "\n";
  }
}

SceneResult run_scene(const std::string& file, const Pipeline& pipeline, int frames, bool picture, bool diagnose,
                      std::ofstream* dump = nullptr, std::ofstream* pair_dump = nullptr) {
  SceneResult result;
  result.name = fs::path(file).stem().string();
  sim::World world(sim::load_scene(file));
  result.objects = world.num_objects();
  const geo::StereoRig rig = world.rig().calibrated();
  const geo::Plane table = table_in_right_camera(world);
  const sim::CameraModel& right = world.camera(1);
  geo::LocationParams locations = pipeline.locations;
  locations.frames = frames;
  geo::LocationFinder finder(rig, table, Eigen::Vector3d(right.t), locations);
  sym::Detector detector(pipeline.params, pipeline.edge);
  std::array<geo::PlaneWarp, 2> warps;
  if (pipeline.table_texture)
    for (int c = 0; c < 2; ++c) warps[c] = geo::plane_warp(rig, c == 0 ? geo::Side::Left : geo::Side::Right, table);

  std::array<std::vector<sim::ImageLine>, 2> truth;
  std::array<std::vector<bool>, 2> visible;
  std::vector<sym::Line> first_left;
  cv::Mat first_image;
  std::vector<int> frames_in_both(world.num_objects(), 0);
  std::array<std::vector<int>, 2> frames_in(
      {std::vector<int>(world.num_objects(), 0), std::vector<int>(world.num_objects(), 0)});
  for (int f = 0; f < frames; ++f) {
    const sim::StereoImages images = world.render_stereo(f == 0);
    std::array<std::vector<sym::Line>, 2> lines;
    std::array<std::vector<bool>, 2> in_lines;
    for (int c = 0; c < 2; ++c) {
      if (f == 0) {
        for (int i = 0; i < world.num_objects(); ++i) {
          truth[c].push_back(world.axis_in_image(i, c));
          visible[c].push_back(cv::countNonZero(images.mask[c] == i + 1) >= kMinVisiblePixels && truth[c].back().valid);
        }
      }
      const cv::Mat& image = images.colour[c];
      nudge::Stopwatch watch;
      const Detection detection = detect(detector, pipeline, image,
                                         {&rig, &table, c == 0 ? geo::Side::Left : geo::Side::Right, &images.colour[1 - c], &warps[c]});
      result.pair_ms += watch.elapsed_ms();
      lines[c] = detection.lines;
      if (dump) dump_peaks(detector, pipeline, image, truth[c], visible[c], {dump, result.name, f, c}, world.camera(c));
      in_lines[c].assign(world.num_objects(), false);
      if (diagnose)
        for (int i = 0; i < world.num_objects(); ++i)
          if (visible[c][i]) diagnose_line(detector, detection, truth[c][i], image.cols, image.rows, &result.line_loss);
      CameraCount& count = result.cameras[c];
      ++count.images;
      count.lines += static_cast<int>(lines[c].size());
      for (int i = 0; i < world.num_objects(); ++i) {
        if (!visible[c][i]) continue;
        ++count.visible;
        for (const auto& l : lines[c]) {
          const auto [d, a] = line_error(l, truth[c][i], image.cols, image.rows);
          if (d <= kLineDistancePx && a <= kLineAngleDeg) {
            ++count.found;
            in_lines[c][i] = true;
            break;
          }
        }
      }
      for (const auto& l : lines[c]) {
        bool near_object = false;
        for (int i = 0; i < world.num_objects() && !near_object; ++i) {
          if (!truth[c][i].valid) continue;
          const auto [d, a] = line_error(l, truth[c][i], image.cols, image.rows);
          near_object = d <= kPhantomDistancePx && a <= kPhantomAngleDeg;
        }
        count.phantoms += !near_object;
      }
    }
    if (f == 0) {
      first_left = lines[0];
      first_image = images.colour[0];
    }
    for (int i = 0; i < world.num_objects(); ++i) {
      frames_in_both[i] += in_lines[0][i] && in_lines[1][i];
      for (int c = 0; c < 2; ++c) frames_in[c][i] += in_lines[c][i];
    }
    if (pair_dump) dump_pairings(rig, table, finder, locations, lines, truth, world, images, result.name, f, pair_dump);
    if (diagnose) {
      const std::vector<geo::PairedAxis> axes = finder.frame_axes(lines[0], lines[1], images.colour[0], images.colour[1]);
      for (int i = 0; i < world.num_objects(); ++i) {
        if (!in_lines[0][i] || !in_lines[1][i]) continue;
        const int il = first_match(lines[0], truth[0][i], images.colour[0].cols, images.colour[0].rows);
        const int ir = first_match(lines[1], truth[1][i], images.colour[1].cols, images.colour[1].rows);
        diagnose_pairing(rig, table, finder.axis_filter(), locations, lines[0], lines[1], il, ir, axes, right,
                         world.object(i).position.head<2>(), &result.pair_loss);
      }
    }
    nudge::Stopwatch watch;
    finder.add_frame(lines[0], lines[1], images.colour[0], images.colour[1]);
    result.pair_ms += watch.elapsed_ms();
  }

  // Candidates against the objects' axes, on the table (world frame).
  std::vector<bool> has_candidate(world.num_objects(), false);
  std::vector<Eigen::Vector2d> drawn;
  std::vector<bool> drawn_is_object;
  for (const geo::Location& location : finder.locations()) {
    const Eigen::Vector3d p = in_world(right, location.position);
    ++result.candidates;
    int nearest = -1;
    double best = kCandidateRadiusM;
    for (int i = 0; i < world.num_objects(); ++i) {
      const double d = (p.head<2>() - world.object(i).position.head<2>()).norm();
      if (d <= best) {
        best = d;
        nearest = i;
      }
    }
    if (nearest < 0) ++result.phantom_candidates;
    else if (has_candidate[nearest]) ++result.duplicate_candidates;
    else {
      has_candidate[nearest] = true;
      ++result.object_candidates;
    }
    drawn.push_back(world.camera(0).project(p));
    drawn_is_object.push_back(nearest >= 0);
  }
  for (bool has : has_candidate) result.objects_without += !has;
  for (int i = 0; i < world.num_objects(); ++i) {
    int near = 0;
    for (const Eigen::Vector3d& hit : finder.intersect_points()) {
      const Eigen::Vector3d p = in_world(right, hit);
      near += (p.head<2>() - world.object(i).position.head<2>()).norm() <= kCandidateRadiusM;
    }
    CandidateLoss& loss = result.candidate_loss;
    if (has_candidate[i]) ++loss.candidate;
    else if (frames_in_both[i] == 0) {
      ++loss.never_both;
      loss.never_both_but_each += frames_in[0][i] > 0 && frames_in[1][i] > 0;
    }
    else if (near == 0) ++loss.no_intersect;
    else ++loss.not_clustered;
  }
  if (picture) draw_frame(first_image, first_left, truth[0], drawn, drawn_is_object, &result.picture);
  return result;
}

struct Summary {
  int scenes = 0, objects = 0;
  std::array<double, 2> in_lines{};  // per camera
  double phantom_lines_per_frame = 0, candidates_share = 0, phantom_candidates_per_scene = 0;
  double lines_per_frame = 0;
  double ms_per_pair = 0;
};

Summary summarise(const std::vector<SceneResult>& results) {
  Summary s;
  std::array<int, 2> visible{}, found{};
  int phantoms = 0, lines = 0, images = 0, with_candidate = 0, phantom_candidates = 0;
  double ms = 0;
  for (const auto& r : results) {
    ms += r.pair_ms;
    ++s.scenes;
    s.objects += r.objects;
    for (int c = 0; c < 2; ++c) {
      visible[c] += r.cameras[c].visible;
      found[c] += r.cameras[c].found;
      phantoms += r.cameras[c].phantoms;
      lines += r.cameras[c].lines;
      images += r.cameras[c].images;
    }
    with_candidate += r.object_candidates;
    phantom_candidates += r.phantom_candidates;
  }
  for (int c = 0; c < 2; ++c) s.in_lines[c] = visible[c] ? static_cast<double>(found[c]) / visible[c] : 0;
  s.phantom_lines_per_frame = images ? static_cast<double>(phantoms) / images : 0;
  s.lines_per_frame = images ? static_cast<double>(lines) / images : 0;
  s.ms_per_pair = images ? ms / (images / 2.0) : 0;
  s.candidates_share = s.objects ? static_cast<double>(with_candidate) / s.objects : 0;
  s.phantom_candidates_per_scene = s.scenes ? static_cast<double>(phantom_candidates) / s.scenes : 0;
  return s;
}

std::string fixed(double v, int digits = 3) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

LineLoss total_line_loss(const std::vector<SceneResult>& rs);
CandidateLoss total_candidate_loss(const std::vector<SceneResult>& rs);

std::string pair_loss_text(const std::vector<SceneResult>& results) {
  PairLoss t;
  for (const SceneResult& r : results) {
    const PairLoss& p = r.pair_loss;
    t.ranked_beyond += p.ranked_beyond, t.tilt += p.tilt, t.range += p.range, t.ring += p.ring;
    t.triangulation += p.triangulation, t.hit_far += p.hit_far, t.overlap += p.overlap, t.foot += p.foot;
    t.taken += p.taken, t.near += p.near;
    t.hit_mm.insert(t.hit_mm.end(), p.hit_mm.begin(), p.hit_mm.end());
  }
  std::sort(t.hit_mm.begin(), t.hit_mm.end());
  auto quantile = [&](double q) { return t.hit_mm.empty() ? 0.0 : t.hit_mm[static_cast<size_t>(q * (t.hit_mm.size() - 1))]; };
  std::ostringstream s;
  s << "object-frames in both cameras' lines: a line ranked beyond the lines paired " << t.ranked_beyond
    << ", axis tilted " << t.tilt << ", out of range " << t.range << ", outside the ring " << t.ring
    << ", no triangulation " << t.triangulation << ", hit > 25 mm away " << t.hit_far << ", height overlap "
    << t.overlap << ", foot above the table " << t.foot << ", a line taken by another pairing " << t.taken
    << ", intersect near " << t.near << "; hit distance mm p50 " << quantile(0.5) << " p75 " << quantile(0.75)
    << " p90 " << quantile(0.9);
  return s.str();
}

std::string losses_text(const std::vector<SceneResult>& results) {
  const LineLoss l = total_line_loss(results);
  const CandidateLoss c = total_candidate_loss(results);
  std::ostringstream s;
  s << "object-frames: in lines " << l.found << ", dropped by verification " << l.verification
    << ", a peak removed by suppression " << l.suppressed << ", a peak ranked below the peaks taken " << l.rank_low
    << ", a peak below min_peak_ratio " << l.below_ratio << ", no peak " << l.no_peak << "; objects: candidate "
    << c.candidate << ", never in both cameras' lines " << c.never_both << " (in each camera's in some frame "
    << c.never_both_but_each << "), no intersect near it "
    << c.no_intersect << ", intersects but no cluster " << c.not_clustered;
  return s.str();
}

std::string summary_json(const Summary& s) {
  std::ostringstream j;
  j << "{\"scenes\": " << s.scenes << ", \"objects\": " << s.objects << ", \"objects_in_lines_share\": {\"left\": "
    << fixed(s.in_lines[0]) << ", \"right\": " << fixed(s.in_lines[1]) << ", \"mean\": "
    << fixed(0.5 * (s.in_lines[0] + s.in_lines[1])) << "}, \"lines_per_frame\": " << fixed(s.lines_per_frame, 2)
    << ", \"phantom_lines_per_frame\": " << fixed(s.phantom_lines_per_frame, 2)
    << ", \"objects_as_candidates_share\": " << fixed(s.candidates_share)
    << ", \"phantom_candidates_per_scene\": " << fixed(s.phantom_candidates_per_scene, 2)
    << ", \"ms_per_stereo_pair\": " << fixed(s.ms_per_pair, 1) << "}";
  return j.str();
}

std::vector<std::string> scene_files(const std::string& dir, const std::string& prefix) {
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix + "_", 0) == 0 && entry.path().extension() == ".yaml") files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// mirror_vote_ms and mirror_speedup from the voting experiment, when it has been run.
std::string mirror_voting_fields() {
  std::ifstream in(results_dir() + "/mirror_voting.json");
  if (!in) return "\"mirror_vote_ms\": null, \"mirror_speedup\": null";
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  auto field = [&](const std::string& key) -> std::string {
    const size_t at = s.find("\"" + key + "\"");
    if (at == std::string::npos) return "null";
    size_t start = s.find(':', at) + 1;
    while (start < s.size() && std::isspace(static_cast<unsigned char>(s[start]))) ++start;
    int depth = 0;
    size_t end = start;
    for (; end < s.size(); ++end) {
      const char ch = s[end];
      if (ch == '{' || ch == '[') ++depth;
      if (ch == '}' || ch == ']') {
        if (depth == 0) break;
        --depth;
      }
      if (ch == ',' && depth == 0) break;
    }
    return s.substr(start, end - start);
  };
  return "\"mirror_vote_ms\": " + field("mirror_vote_ms") + ", \"mirror_speedup\": " + field("mirror_speedup");
}


std::string summary_row(const std::string& label, const Summary& s) {
  std::ostringstream md;
  md << "| " << label << " | " << s.scenes << " | " << s.objects << " | " << fixed(100 * s.in_lines[0], 1) << " % | "
     << fixed(100 * s.in_lines[1], 1) << " % | " << fixed(s.lines_per_frame, 1) << " | " << fixed(s.phantom_lines_per_frame, 2)
     << " | " << fixed(100 * s.candidates_share, 1) << " % | " << fixed(s.phantom_candidates_per_scene, 2) << " | "
     << fixed(s.ms_per_pair, 0) << " |\n";
  return md.str();
}

std::string per_scene_json(const std::vector<SceneResult>& rs) {
  std::ostringstream json;
  json << "[\n";
  for (size_t i = 0; i < rs.size(); ++i) {
    const SceneResult& r = rs[i];
    json << "    {\"scene\": \"" << r.name << "\", \"objects\": " << r.objects << ", \"in_lines\": [" << r.cameras[0].found << ", "
         << r.cameras[1].found << "], \"visible\": [" << r.cameras[0].visible << ", " << r.cameras[1].visible
         << "], \"phantom_lines\": " << r.cameras[0].phantoms + r.cameras[1].phantoms << ", \"candidates\": " << r.candidates
         << ", \"object_candidates\": " << r.object_candidates << ", \"objects_without\": " << r.objects_without
         << ", \"phantom_candidates\": " << r.phantom_candidates << "}" << (i + 1 < rs.size() ? "," : "") << "\n";
  }
  json << "  ]";
  return json.str();
}

std::string per_scene_md(const std::vector<SceneResult>& rs) {
  std::ostringstream md;
  md << "| scene | objects | in left / right lines (object-frames) | phantom lines | candidates | objects | objects without | phantoms |\n"
     << "|---|---|---|---|---|---|---|---|\n";
  for (const SceneResult& r : rs)
    md << "| " << r.name << " | " << r.objects << " | " << r.cameras[0].found << "/" << r.cameras[0].visible << ", "
       << r.cameras[1].found << "/" << r.cameras[1].visible << " | " << r.cameras[0].phantoms + r.cameras[1].phantoms << " | "
       << r.candidates << " | " << r.object_candidates << " | " << r.objects_without << " | " << r.phantom_candidates << " |\n";
  return md.str();
}

LineLoss total_line_loss(const std::vector<SceneResult>& rs) {
  LineLoss l;
  for (const auto& r : rs) {
    l.found += r.line_loss.found;
    l.verification += r.line_loss.verification;
    l.suppressed += r.line_loss.suppressed;
    l.rank_low += r.line_loss.rank_low;
    l.below_ratio += r.line_loss.below_ratio;
    l.no_peak += r.line_loss.no_peak;
  }
  return l;
}

CandidateLoss total_candidate_loss(const std::vector<SceneResult>& rs) {
  CandidateLoss c;
  for (const auto& r : rs) {
    c.candidate += r.candidate_loss.candidate;
    c.never_both += r.candidate_loss.never_both;
    c.never_both_but_each += r.candidate_loss.never_both_but_each;
    c.no_intersect += r.candidate_loss.no_intersect;
    c.not_clustered += r.candidate_loss.not_clustered;
  }
  return c;
}

using Results = std::map<std::string, std::map<std::string, std::vector<SceneResult>>>;

void write_report(const Results& results, int frames, int dev_frames, const AfterOptions& o) {
  const Summary before = summarise(results.at("eval").at("before")), after = summarise(results.at("eval").at("after"));
  const Summary held_before = summarise(results.at("held").at("before")), held_after = summarise(results.at("held").at("after"));
  std::ostringstream json;
  json << "{\n  \"machine\": \"" << machine_description() << "\",\n  \"date\": \"" << today() << "\",\n  \"frames_per_scene\": "
       << frames << ",\n  \"scenes\": " << after.scenes << ",\n  \"objects\": " << after.objects
       << ",\n  \"objects_in_lines_share\": {\"left\": " << fixed(after.in_lines[0]) << ", \"right\": " << fixed(after.in_lines[1])
       << ", \"mean\": " << fixed(0.5 * (after.in_lines[0] + after.in_lines[1])) << "},\n  \"phantom_lines_per_frame\": "
       << fixed(after.phantom_lines_per_frame, 2) << ",\n  \"objects_as_candidates_share\": " << fixed(after.candidates_share)
       << ",\n  \"phantom_candidates_per_scene\": " << fixed(after.phantom_candidates_per_scene, 2) << ",\n  "
       << mirror_voting_fields() << ",\n  \"before\": " << summary_json(before) << ",\n  \"after\": " << summary_json(after)
       << ",\n  \"first_round_after\": {\"objects_in_lines_share\": {\"left\": 0.542, \"right\": 0.528, \"mean\": 0.535}, "
          "\"objects_as_candidates_share\": 0.391, \"phantom_candidates_per_scene\": 1.00, \"note\": \"reported 2026-11-24 "
          "before the second round (docs/clutter.md)\"}"
       << ",\n  \"per_scene\": " << per_scene_json(results.at("eval").at("after"))
       << ",\n  \"held_out_2001_2012\": {\"before\": " << summary_json(held_before) << ", \"after\": " << summary_json(held_after)
       << ",\n  \"per_scene\": " << per_scene_json(results.at("held").at("after")) << "}";
  const LineLoss lb = total_line_loss(results.at("dev").at("before")), la = total_line_loss(results.at("dev").at("after"));
  const CandidateLoss cb = total_candidate_loss(results.at("dev").at("before")), ca = total_candidate_loss(results.at("dev").at("after"));
  auto loss_json = [](const LineLoss& l, const CandidateLoss& c) {
    std::ostringstream j;
    j << "{\"object_frames\": {\"in_lines\": " << l.found << ", \"dropped_by_verification\": " << l.verification
      << ", \"removed_by_suppression\": " << l.suppressed << ", \"ranked_below_peaks_taken\": " << l.rank_low
      << ", \"below_min_peak_ratio\": " << l.below_ratio << ", \"no_peak\": " << l.no_peak << "}, \"objects\": {\"candidate\": "
      << c.candidate << ", \"never_in_both_cameras_lines\": " << c.never_both << ", \"no_intersect_near\": " << c.no_intersect
      << ", \"intersects_not_clustered\": " << c.not_clustered << "}}";
    return j.str();
  };
  json << ",\n  \"development_losses\": {\"frames_per_scene\": " << dev_frames << ", \"before\": " << loss_json(lb, cb)
       << ", \"after\": " << loss_json(la, ca) << "}\n}\n";
  write_result("clutter.json", json.str());

  std::ostringstream md;
  md << "# Busy tables: symmetry lines and candidates (issue 14)\n\n"
     << "`nudge-exp-clutter --set both`, " << today() << ". " << machine_description() << ". Two held-out families: "
     << "`eval_*` (seeds 1001-1010, fixed before the first round) and `held_*` (seeds 2001-2012, fixed before the "
     << "second round changed anything; docs/clutter.md), " << frames
     << " noisy stereo pairs per scene (a survey takes 25; fewer here: 8 engineers shared the 2 cores), each run once. Objects \"in the lines\": the true axis within " << kLineDistancePx
     << " px (at its middle) and " << kLineAngleDeg << " deg of one of the camera's lines, over the objects with at least "
     << kMinVisiblePixels << " visible pixels; phantom lines: further than " << kPhantomDistancePx << " px or "
     << kPhantomAngleDeg << " deg from every axis; a candidate is an object within " << kCandidateRadiusM * 1000
     << " mm of its axis. ms / pair: both cameras' detection (edges, voting, peaks, verification) and the pair's "
        "intersects, single-threaded, on this machine while others shared it (load average about 10 on 2 cores: the figures vary by 4x between runs of the same pipeline, compare within a row pair only roughly).\n\n"
     << "| pipeline | scenes | objects | in left lines | in right lines | lines / image | phantom lines / image | objects as candidates | phantom candidates / scene | ms / pair |\n"
     << "|---|---|---|---|---|---|---|---|---|---|\n"
     << summary_row("eval 1001-1010, before issue 14", before)
     << "| eval 1001-1010, first round (reported before; docs/clutter.md) | 10 | 64 | 54.2 % | 52.8 % | 8.0 | 3.77 | 39.1 % | 1.00 | |\n"
     << summary_row("eval 1001-1010, after", after) << summary_row("held 2001-2012, before issue 14", held_before)
     << summary_row("held 2001-2012, after", held_after)
     << "\nTargets (issue 14): >= 90 % of objects in each camera's lines, >= 95 % of objects a candidate, <= 1 phantom "
        "candidate per scene.\n\n"
     << "\"after\": " << o.candidates << " accumulator peaks (suppression " << o.suppress << "), only those within "
     << o.upright << " deg of an upright axis' image verified, " << o.keep << " kept" << (o.snap ? ", snapped upright" : "")
     << (o.support_gap > o.band_gap ? ", support segments joined across gaps up to " + fixed(o.support_gap, 0) + " px" : "")
     << "; " << o.candidate_lines << " lines per image to CANDIDATES"
     << (o.stereo_check ? ", stereo check (overlap " + fixed(o.min_overlap, 2) + ", foot " + fixed(o.max_foot, 2) + " m)" : ", no stereo check")
     << (o.min_agreement > 0 ? ", stereo appearance along the axis (agreement " + fixed(o.min_agreement, 2) + ", tolerance " +
                                   fixed(o.agreement_tolerance, 0) + ", waived at overlap " + fixed(o.agreement_waived, 2) + ")"
                             : "")
     << ", QT min fraction " << fixed(o.min_fraction, 2) << " (docs/clutter.md).\n\n"
     << "## Where objects are lost (development family, seeds 1-40, " << dev_frames << " stereo pairs per scene)\n\n"
     << "Per visible object and camera frame: its axis among the lines; among the accumulator's peaks but dropped by the "
        "verification (with the upright check: by it or by the verification); a peak of the accumulator (suppression 1, "
        "no peak ratio) ranked within the peaks taken but removed by the coarser suppression; ranked below the peaks "
        "taken; below the peak ratio; no peak at all (edges, voting, or a partly hidden outline). Per object: a "
        "candidate; never in both cameras' lines in one frame; in both but no table intersect within 25 mm (stereo "
        "pairing, the stereo check, the upright / workspace filter); intersects but no cluster.\n\n"
     << "| pipeline | object-frames in lines | dropped by verification | removed by suppression | ranked below | below ratio | no peak | objects: candidate | never in both | no intersect | not clustered |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& [label, l, c] : {std::tuple<std::string, LineLoss, CandidateLoss>{"before issue 14", lb, cb}, {"after", la, ca}})
    md << "| " << label << " | " << l.found << " | " << l.verification << " | " << l.suppressed << " | " << l.rank_low << " | "
       << l.below_ratio << " | " << l.no_peak << " | " << c.candidate << " | " << c.never_both << " | " << c.no_intersect
       << " | " << c.not_clustered << " |\n";
  md << "\n## Per scene (eval, after)\n\n" << per_scene_md(results.at("eval").at("after"))
     << "\n## Per scene (held, after)\n\n" << per_scene_md(results.at("held").at("after"))
     << "\nOne left frame per scene (half size): true axes green, the frame's lines red (their support segments), "
        "candidates projected from the table: cyan = an object, magenta = a phantom.\n\n";
  for (const std::string family : {"eval", "held"})
    for (const SceneResult& r : results.at(family).at("after")) {
      cv::Mat half;
      cv::resize(r.picture, half, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
      write_png("clutter_" + r.name + ".png", half);
      md << "![" << r.name << "](clutter_" << r.name << ".png)\n";
    }
  write_result("clutter.md", md.str());
}
}  // namespace

int main(int argc, char** argv) {
  std::string set = "both", scenes_dir = std::string(NUDGE_SOURCE_DIR) + "/common/sim/scenes/clutter";
  int frames = 25, dev_frames = 2;
  bool no_write = false, skip_before = false, diagnose = false;
  int seed_min = 0, seed_max = 1 << 30;
  std::string pictures, dump_file, pair_dump_file;
  AfterOptions after_options;
  std::vector<double> canny;
  nudge::Flags flags("nudge-exp-clutter", "Symmetry lines and candidates on busy tables (issue 14).");
  flags.add_string("set", &set, "scene families: both (the report: eval and held, and the losses on dev), or eval, held, dev alone");
  flags.add_string("scenes", &scenes_dir, "directory of the clutter scenes");
  flags.add_int("frames", &frames, "stereo pairs per scene (a survey's)");
  flags.add_int("dev-frames", &dev_frames, "with --set both: stereo pairs per development scene for the loss breakdown");
  flags.add_bool("no-write", &no_write, "print only; write no result files");
  flags.add_string("pictures", &pictures, "also write each scene's picture (after) to this directory");
  flags.add_string("dump", &dump_file, "write every accumulator peak's features and truth to this CSV (tuning)");
  flags.add_string("dump-pairings", &pair_dump_file, "write every valid pairing's stereo-check numbers and truth to this CSV (tuning)");
  flags.add_bool("diagnose", &diagnose, "print where each missed object was lost (stage by stage)");
  flags.add_int("seed-min", &seed_min, "only scenes whose seed (file name's number) is at least this");
  flags.add_int("seed-max", &seed_max, "only scenes whose seed is at most this");
  flags.add_bool("skip-before", &skip_before, "measure only the issue-14 pipeline (with --no-write, for tuning)");
  AfterOptions& a = after_options;
  double verify_flag = 1, colour_flag = 1, stereo_flag = 1, refine_flag = a.refine, snap_flag = a.snap, table_texture_flag = 0;
  flags.add_double("table-texture", &table_texture_flag, "1 = leave the table's own texture out of the edges (both pipelines)");
  flags.add_double("snap", &snap_flag, "after: 1 = turn the verified lines into images of upright axes");
  flags.add_double("refine", &refine_flag, "after: 1 = refit each verified line to its band's pair midpoints");
  flags.add_double("upright", &a.upright, "after: > 0: verify only peaks within this many deg of an upright axis' image");
  flags.add_double("refine-max", &a.refine_max, "after: largest refit move, deg");
  flags.add_double("dmin", &a.dmin, "after: minimum pairing distance, px");
  flags.add_double("dmax", &a.dmax, "after: maximum pairing distance, px");
  flags.add_double("blur", &a.blur, "after: Gaussian blur before Canny");
  flags.add_doubles("canny", &canny, 2, "after: Canny thresholds LOW HIGH");
  flags.add_int("candidates", &a.candidates, "after: peaks taken from the accumulator");
  flags.add_int("suppress", &a.suppress, "after: non-maximum suppression half-size, px and deg");
  flags.add_double("verify", &verify_flag, "after: 1 = verify the peaks (local support, appearance) and keep the best, 0 = off");
  flags.add_int("keep", &a.keep, "after: lines kept per image after verification");
  flags.add_double("appearance-weight", &a.appearance_weight, "after: exponent of the appearance agreement");
  flags.add_double("band-weight", &a.band_weight, "after: exponent of the largest band's share of the pairs");
  flags.add_double("min-appearance", &a.min_appearance, "after: drop lines below this appearance agreement");
  flags.add_double("colour-tolerance", &a.colour_tolerance, "after: L1 BGR tolerance of mirrored samples");
  flags.add_double("band-gap", &a.band_gap, "after: gap that splits bands along a line, px");
  flags.add_double("support-gap", &a.support_gap, "after: gaps up to this join bands into a line's support segment, px (0: the largest band alone)");
  flags.add_double("verify-suppress", &a.verify_suppress, "after: verified lines closer than this (px, and 3 deg) to a better one are dropped");
  flags.add_double("colour-edges", &colour_flag, "after: 1 = Canny on the colour image, 0 = on grey");
  flags.add_double("stereo-check", &stereo_flag, "after: 1 = pair lines only when their support heights agree, 0 = off");
  flags.add_double("min-overlap", &a.min_overlap, "after: stereo check, least overlap / union of the heights");
  flags.add_double("max-foot", &a.max_foot, "after: stereo check, lowest support end at most this far from the table, m");
  flags.add_int("candidate-lines", &a.candidate_lines, "after: lines per image paired for CANDIDATES");
  flags.add_double("min-agreement", &a.min_agreement, "after: least share of an axis' heights where both images agree (0: off)");
  flags.add_int("agreement-window", &a.agreement_window, "after: half-size of the colour window of the stereo appearance check, px");
  flags.add_double("agreement-waived", &a.agreement_waived, "after: support overlap at which the stereo appearance check is waived (> 1: never)");
  flags.add_double("agreement-tolerance", &a.agreement_tolerance, "after: L1 BGR tolerance of the stereo appearance check");
  flags.add_double("min-fraction", &a.min_fraction, "after: smallest QT cluster, share of all intersects");
  try {
    if (!flags.parse(argc, argv)) return 0;
    if (set != "eval" && set != "dev" && set != "held" && set != "both")
      throw nudge::FlagError("--set must be both (the report), eval, held or dev");
    if (dev_frames < 1) throw nudge::FlagError("--dev-frames must be >= 1");
    if (frames < 1) throw nudge::FlagError("--frames must be >= 1");
    if (skip_before && !no_write) throw nudge::FlagError("--skip-before needs --no-write");
    a.verify = verify_flag != 0;
    a.colour_edges = colour_flag != 0;
    a.stereo_check = stereo_flag != 0;
    a.refine = refine_flag != 0;
    a.snap = snap_flag != 0;
    if (!canny.empty()) {
      a.canny_low = canny[0];
      a.canny_high = canny[1];
    }
  } catch (const nudge::FlagError& e) {
    std::cerr << e.what() << "\n" << flags.help();
    return 2;
  }
  // The families to run: --set both is the report (the two held-out families, and the loss
  // breakdown on the development family); eval, held or dev alone are for looking.
  std::vector<std::string> sets = set == "both" ? std::vector<std::string>{"eval", "held", "dev"} : std::vector<std::string>{set};
  std::vector<Pipeline> pipelines = {before_issue14(), after_issue14(after_options)};
  for (Pipeline& p : pipelines) p.table_texture = table_texture_flag != 0;
  if (skip_before) pipelines.erase(pipelines.begin());
  std::map<std::string, std::map<std::string, std::vector<SceneResult>>> results;  // [set][pipeline]
  std::ofstream dump;
  if (!dump_file.empty()) {
    dump.open(dump_file);
    dump << "scene,frame,camera,rank,votes,pairs,band_share,appearance,band_len,rows,smooth,polarity,r,theta,label,tilt\n";
  }
  std::ofstream pair_dump;
  if (!pair_dump_file.empty()) {
    pair_dump.open(pair_dump_file);
    pair_dump << "agree60,agree30,agree_fixed,scene,frame,il,ir,left_object,right_object,nearest,hit_mm,left_low,left_high,right_low,right_high,"
                 "axis_tilt,left_tilt,right_tilt,left_votes,right_votes\n";
  }
  std::map<std::string, std::vector<std::string>> files_of;
  int steps = 0;
  for (const std::string& family : sets) {
    std::vector<std::string> files = scene_files(scenes_dir, family);
    files.erase(std::remove_if(files.begin(), files.end(),
                               [&](const std::string& f) {
                                 const std::string stem = fs::path(f).stem().string();
                                 const int seed = std::stoi(stem.substr(stem.rfind('_') + 1));
                                 return seed < seed_min || seed > seed_max;
                               }),
                files.end());
    if (files.empty()) {
      std::cerr << "nudge-exp-clutter: no " << family << "_*.yaml scenes in " << scenes_dir << "\n";
      return 1;
    }
    steps += static_cast<int>(pipelines.size() * files.size());
    files_of[family] = files;
  }
  nudge::Progress progress("nudge-exp-clutter", steps);
  for (const std::string& family : sets) {
    // In the report the development family only gives the loss breakdown, over fewer frames.
    const bool breakdown_only = set == "both" && family == "dev";
    for (const Pipeline& pipeline : pipelines) {
      for (const std::string& file : files_of[family]) {
        progress.step(pipeline.name + " " + fs::path(file).stem().string());
        results[family][pipeline.name].push_back(
            run_scene(file, pipeline, breakdown_only ? dev_frames : frames, pipeline.name == "after" && !breakdown_only,
                      diagnose || breakdown_only, dump.is_open() && pipeline.name == "after" ? &dump : nullptr,
                      pair_dump.is_open() && pipeline.name == "after" ? &pair_dump : nullptr));
        const SceneResult& r = results[family][pipeline.name].back();
        if (!pictures.empty() && !r.picture.empty()) cv::imwrite(pictures + "/" + r.name + ".png", r.picture);
        std::ostringstream detail;
        detail << pipeline.name << " " << r.name << ": " << r.objects << " objects; in lines L " << r.cameras[0].found
               << "/" << r.cameras[0].visible << " R " << r.cameras[1].found << "/" << r.cameras[1].visible
               << "; phantom lines " << r.cameras[0].phantoms + r.cameras[1].phantoms << "/"
               << r.cameras[0].lines + r.cameras[1].lines << "; candidates " << r.candidates << ": objects "
               << r.object_candidates << ", duplicates " << r.duplicate_candidates << ", phantoms "
               << r.phantom_candidates << ", objects without " << r.objects_without;
        if (!breakdown_only || diagnose) progress.note(detail.str());
      }
      progress.note(family + " " + pipeline.name + ": " + summary_json(summarise(results[family][pipeline.name])));
      if (diagnose || breakdown_only) progress.note(family + " " + pipeline.name + " losses: " + losses_text(results[family][pipeline.name]));
      if (diagnose) progress.note(family + " " + pipeline.name + " pairings: " + pair_loss_text(results[family][pipeline.name]));
    }
  }
  progress.finish(set + " scenes, " + std::to_string(pipelines.size()) + " pipeline(s)");
  if (no_write) return 0;
  if (set != "both") {
    std::cerr << "(only --set both writes the report)\n";
    return 0;
  }
  write_report(results, frames, dev_frames, after_options);
  return 0;
}
