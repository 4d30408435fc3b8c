// triangulation: stereo symmetry lines -> 3D symmetry axes (thesis sec. 4.3) and, on request,
// candidate object locations on the table (sec. 6.2).
//   SYMMETRY_LEFT + SYMMETRY_RIGHT (paired by utime) -> AXES (axes_t), every stereo pair
//   CANDIDATES_REQUEST (candidates_request_t) -> gather N pairs -> CANDIDATES (candidates_t), once
//   with --stereo-appearance also CAMERA_LEFT + CAMERA_RIGHT (image_t, the lines' images, found by
//   utime): a pairing counts for CANDIDATES only where both images agree along its axis
// With a table plane, positions are in the table frame (z up along the table normal, origin at the
// arm base's foot on the table, else below the right camera; x = the right camera's x projected
// onto the table). Without one, AXES are in the right camera's frame with NaN table points.
// The table plane and arm base come from --table-plane / --arm-base, else from the calibration
// file's optional `table_plane` / `arm_base` fields (see nudge/geometry/workspace.hpp); the
// workspace ring around the arm base from --workspace FILE (robot::Workspace, the arm's), with
// --ring-inner / --ring-outer as overrides.
#include <array>
#include <cmath>
#include <deque>
#include <limits>
#include <optional>

#include "nudge/axes_t.hpp"
#include "nudge/bus/axes_convert.hpp"
#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/bus/symmetry_convert.hpp"
#include "nudge/candidates_request_t.hpp"
#include "nudge/candidates_t.hpp"
#include "nudge/geometry/interesting_locations.hpp"
#include "nudge/geometry/stereo_pairing.hpp"
#include "nudge/geometry/workspace.hpp"
#include "nudge/image_t.hpp"
#include "nudge/log.hpp"
#include "nudge/robot/workspace_flags.hpp"
#include "nudge/symmetry_lines_t.hpp"

using namespace nudge;
namespace geo = nudge::geometry;

namespace {

struct Options {
  std::string calibration, left_channel = bus::channel::SYMMETRY_LEFT,
              right_channel = bus::channel::SYMMETRY_RIGHT;
  // With --stereo-appearance: the images the lines were found in (paired with them by utime).
  std::string left_image_channel = bus::channel::CAMERA_LEFT, right_image_channel = bus::channel::CAMERA_RIGHT;
  std::vector<double> table_plane, arm_base;
  int lines = 0, buffer = 16;
  geo::AxisFilter filter;             // AXES: thesis ch. 4 (15 deg, within reach)
  geo::TriangulationParams triangulation;
  geo::LocationParams locations;      // CANDIDATES: thesis ch. 6
  std::string column_lines = "counted";
};

// n . p + d = 0 from --table-plane NX NY NZ D (right camera frame).
geo::Plane plane_from_flag(const std::vector<double>& v) {
  try {
    return geo::plane_from_coefficients(Eigen::Vector4d(v[0], v[1], v[2], v[3]));
  } catch (const std::invalid_argument& e) {
    throw FlagError(std::string("--table-plane: ") + e.what());
  }
}

// The table and arm base from the flags, else from the calibration file's optional fields.
geo::Workspace workspace_of(const Options& opt) {
  geo::Workspace workspace = geo::load_workspace(opt.calibration);
  if (!opt.table_plane.empty()) workspace.table = plane_from_flag(opt.table_plane);
  if (!opt.arm_base.empty()) workspace.arm_base = Eigen::Vector3d(opt.arm_base[0], opt.arm_base[1], opt.arm_base[2]);
  return workspace;
}

class Triangulation {
 public:
  Triangulation(bus::Service& service, const Options& opt)
      : service_(service), opt_(opt), rig_(geo::load_rig(opt.calibration)), pairer_(opt.buffer) {
    const geo::Workspace workspace = workspace_of(opt);
    table_ = workspace.table;
    arm_base_ = workspace.arm_base;
    if (table_) frame_.emplace(*table_, arm_base_);
    log::info() << "rig " << opt.calibration << ": baseline " << rig_.T.norm() << " m; "
                << (table_ ? "table frame output" : "no table plane: AXES in the right camera frame, no candidates")
                << (table_ && !arm_base_ ? "; no arm base: candidates without the workspace ring" : "")
                << (table_ && arm_base_ ? "; candidates in the " + std::to_string(opt.locations.ring_inner_m) + "-" +
                                              std::to_string(opt.locations.ring_outer_m) + " m workspace ring"
                                        : std::string());
  }

  void subscribe() {
    auto& subs = service_.subscriptions();
    subs.subscribe<symmetry_lines_t>(opt_.left_channel, [this](const symmetry_lines_t& m, const std::string& ch) {
      on_lines(geo::Side::Left, m, ch);
    });
    subs.subscribe<symmetry_lines_t>(opt_.right_channel, [this](const symmetry_lines_t& m, const std::string& ch) {
      on_lines(geo::Side::Right, m, ch);
    });
    subs.subscribe<candidates_request_t>(bus::channel::CANDIDATES_REQUEST,
                                         [this](const candidates_request_t& m, const std::string&) { on_request(m); });
    if (opt_.locations.min_axis_colour_agreement <= 0) return;
    subs.subscribe<image_t>(opt_.left_image_channel, [this](const image_t& m, const std::string& ch) {
      on_image(geo::Side::Left, m, ch);
    });
    subs.subscribe<image_t>(opt_.right_image_channel, [this](const image_t& m, const std::string& ch) {
      on_image(geo::Side::Right, m, ch);
    });
  }

 private:
  using Lines = std::vector<symmetry::Line>;

  // Checks the message against the calibration; throws (counted and skipped by the bus) if unusable.
  Lines lines_of(const symmetry_lines_t& msg, const std::string& channel, const geo::Camera& camera) {
    if (msg.width != camera.width || msg.height != camera.height)
      throw std::runtime_error("utime " + std::to_string(msg.utime) + ": image " + std::to_string(msg.width) +
                               "x" + std::to_string(msg.height) + " but the calibration is for " +
                               std::to_string(camera.width) + "x" + std::to_string(camera.height));
    Lines lines;
    for (const auto& l : msg.lines) lines.push_back(bus::from_message(l));
    for (size_t i = 0; i < lines.size(); ++i) {
      if (geo::is_finite(lines[i])) continue;
      ++service_.counters().errors;  // the rest of the message is still usable
      log::error() << channel << " utime " << msg.utime << ": line " << i
                   << " has non-finite values; its pairings are skipped";
    }
    return lines;
  }

  // The stereo appearance check compares the images the lines were found in: while a candidates
  // request gathers, the last few of each camera are kept, to be found by the lines' utime (between
  // surveys nothing reads them, so they are not decoded).
  void on_image(geo::Side side, const image_t& msg, const std::string& channel) {
    if (!finder_) return;
    const geo::Camera& camera = side == geo::Side::Left ? rig_.left : rig_.right;
    cv::Mat image = bus::to_mat(msg);  // throws naming the image: counted and skipped by the bus
    if (image.cols != camera.width || image.rows != camera.height)
      throw std::runtime_error(channel + " utime " + std::to_string(msg.utime) + ": image " +
                               std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                               " but the calibration is for " + std::to_string(camera.width) + "x" +
                               std::to_string(camera.height));
    auto& kept = images_[side == geo::Side::Left ? 0 : 1];
    kept.emplace_back(msg.utime, std::move(image));
    while (static_cast<int>(kept.size()) > opt_.buffer) kept.pop_front();
  }

  const cv::Mat* image_at(geo::Side side, int64_t utime) const {
    for (const auto& [t, image] : images_[side == geo::Side::Left ? 0 : 1])
      if (t == utime) return &image;
    return nullptr;
  }

  void on_lines(geo::Side side, const symmetry_lines_t& msg, const std::string& channel) {
    Lines lines = lines_of(msg, channel, side == geo::Side::Left ? rig_.left : rig_.right);
    const int64_t dropped_before = pairer_.dropped();
    auto pair = pairer_.add(side, msg.utime, std::move(lines));
    if (pairer_.dropped() > dropped_before)
      log::warn() << "dropped " << pairer_.dropped() - dropped_before << " unmatched symmetry message(s) ("
                  << pairer_.dropped() << " so far)";
    if (!pair) return;
    ++pairs_;
    publish_axes(pair->utime, pair->left, pair->right);
    if (finder_ && pair->utime < request_utime_) {
      ++stale_pairs_;  // taken before the request: not the table as it is now
    } else if (finder_) {
      gather(pair->utime, pair->left, pair->right);
    }
    service_.set_status("pairs " + std::to_string(pairs_) + ", unmatched " + std::to_string(pairer_.dropped()));
  }

  void publish_axes(int64_t utime, const Lines& left, const Lines& right) {
    geo::PairingResult result = geo::triangulate_pairings(rig_, left, right, table_ ? &*table_ : nullptr,
                                                          opt_.filter, opt_.triangulation, opt_.lines);
    // Busy tables: every line paired with every line gives ~140 axes a frame from 12 lines, most
    // of them between two objects or in the table's texture, which the supervisor's settled-axes
    // check then takes for the nudged object. The stereo check keeps each line's most consistent
    // pairing only, as for CANDIDATES.
    if (opt_.locations.stereo_check && table_)
      result.axes = geo::consistent_pairings(rig_, left, right, result, *table_, opt_.locations);
    for (const auto& why : result.rejections) log::debug() << "utime " << utime << ": " << why;
    const axes_t msg = bus::to_message(result, utime, frame_ ? &*frame_ : nullptr);
    service_.publish(bus::channel::AXES, msg);
    log::debug() << "utime " << utime << ": " << msg.num_axes << " of " << msg.num_pairings << " pairings valid";
  }

  void on_request(const candidates_request_t& request) {
    if (!table_) {
      throw std::runtime_error("candidate locations need the table plane (--table-plane); request ignored");
    }
    geo::LocationParams params = opt_.locations;
    if (request.frames > 0) params.frames = request.frames;
    if (request.lines_per_image > 0) params.lines_per_image = request.lines_per_image;
    if (!(request.max_line_tilt_deg <= 0)) {  // positive, or NaN: refused below, not ignored
      if (!(request.max_line_tilt_deg <= 90))
        throw std::runtime_error("max_line_tilt_deg " + std::to_string(request.max_line_tilt_deg) +
                                 " is not in (0, 90]; request ignored");
      params.max_line_tilt_deg = request.max_line_tilt_deg;
    }
    for (int i = 0; i < request.num_explored; ++i) {
      const Eigen::Vector3d place(request.explored[i][0], request.explored[i][1], request.explored[i][2]);
      if (!place.allFinite()) throw std::runtime_error("explored place " + std::to_string(i) + " is not finite; request ignored");
      params.explored.push_back(frame_->to_camera(place));
    }
    if (finder_) log::warn() << "a new candidates request replaces the one in progress";
    finder_.emplace(rig_, *table_, arm_base_, params, opt_.triangulation);
    request_utime_ = request.utime;
    stale_pairs_ = 0;
    log::info() << "candidates requested: gathering " << params.frames << " stereo pairs, " << params.lines_per_image
                << " lines per image"
                << (params.max_line_tilt_deg > 0 ? ", within " + std::to_string(params.max_line_tilt_deg) + " deg of upright" : std::string())
                << (params.explored.empty() ? std::string()
                                          : ", leaving out the lines of " + std::to_string(params.explored.size()) + " explored object(s)");
  }

  void gather(int64_t utime, const Lines& left, const Lines& right) {
    if (opt_.locations.min_axis_colour_agreement > 0) {
      const cv::Mat *left_image = image_at(geo::Side::Left, utime), *right_image = image_at(geo::Side::Right, utime);
      if (!left_image || !right_image) {
        ++frames_without_images_;
        log::warn() << "utime " << utime << ": no " << (left_image ? opt_.right_image_channel : opt_.left_image_channel)
                    << " image of the lines' moment for the stereo appearance check; the pair is not gathered ("
                    << frames_without_images_ << " so far)";
        return;
      }
      finder_->add_frame(left, right, *left_image, *right_image);
    } else {
      finder_->add_frame(left, right);
    }
    if (!finder_->complete()) return;
    candidates_t msg;
    msg.utime = utime;
    msg.frames_used = finder_->frames();
    msg.intersects = finder_->intersects();
    for (const geo::Location& loc : finder_->locations()) {
      const Eigen::Vector3d p = frame_->to_table(loc.position);
      msg.position.push_back({p.x(), p.y(), p.z()});
      msg.cluster_size.push_back(loc.support);
    }
    msg.num_candidates = static_cast<int32_t>(msg.position.size());
    service_.publish(bus::channel::CANDIDATES, msg);
    log::info() << "candidates: " << msg.num_candidates << " locations from " << msg.intersects << " intersects over "
                << msg.frames_used << " stereo pairs"
                << (stale_pairs_ ? " (skipped " + std::to_string(stale_pairs_) + " stereo pair(s) taken before the request)"
                                 : std::string());
    finder_.reset();
  }

  bus::Service& service_;
  const Options& opt_;
  geo::StereoRig rig_;
  std::optional<geo::Plane> table_;
  std::optional<Eigen::Vector3d> arm_base_;
  std::optional<geo::TableFrame> frame_;
  geo::StereoPairer<Lines> pairer_;
  std::optional<geo::LocationFinder> finder_;
  int64_t pairs_ = 0;
  int64_t request_utime_ = 0;  // the candidates request's: pairs taken before it are not gathered
  int64_t stale_pairs_ = 0;    // such pairs since the request
  int64_t frames_without_images_ = 0;  // pairs not gathered: their images never came
  std::array<std::deque<std::pair<int64_t, cv::Mat>>, 2> images_;  // left, right: (utime, image)
};

void add_flags(Flags& f, Options& o) {
  f.add_string("calibration", &o.calibration, "stereo rig file (nudge-calibrate's YAML); required");
  f.add_doubles("table-plane", &o.table_plane, 4,
                "table plane NX NY NZ D (n.p + D = 0, right camera frame, m); default: the file's table_plane");
  f.add_doubles("arm-base", &o.arm_base, 3,
                "arm base X Y Z (right camera frame, m; centre of the workspace ring); default: the file's arm_base");
  f.add_string("left-channel", &o.left_channel, "left symmetry lines");
  f.add_string("right-channel", &o.right_channel, "right symmetry lines");
  f.add_int("lines", &o.lines, "AXES: strongest lines per image to pair (0: all)");
  f.add_int("buffer", &o.buffer, "unmatched messages kept per side while waiting for the partner");
  f.add_double("max-tilt", &o.filter.max_tilt_deg, "AXES: max angle from the table normal, degrees");
  f.add_double("max-range", &o.filter.max_range_m, "max distance of a table point from the right camera, m");
  f.add_double("zmax", &o.triangulation.zmax, "depth of the back-projected triangles, m");
  f.add_int("plane-samples", &o.triangulation.plane_samples, "samples fitted per line (0: thesis end points)");
  f.add_int("candidate-frames", &o.locations.frames, "CANDIDATES: stereo pairs gathered per request");
  f.add_int("candidate-lines", &o.locations.lines_per_image, "CANDIDATES: strongest lines per image");
  f.add_double("candidate-tilt", &o.locations.max_tilt_deg, "CANDIDATES: max angle from the table normal, degrees");
  f.add_double("candidate-line-tilt", &o.locations.max_line_tilt_deg,
               "CANDIDATES: pair only lines that are within this many degrees of the image of an upright axis "
               "(0: any line, the thesis)");
  f.add_string("candidate-column-lines", &o.column_lines,
               "CANDIDATES: the arm base column's lines (within --candidate-column-px of the image of its axis): "
               "counted (like any line, the thesis), dropped, or uncounted (paired, but not among the "
               "--candidate-lines); needs the arm base");
  f.add_double("candidate-column-px", &o.locations.column_line_px,
               "CANDIDATES: a line this near the image of the arm base column's axis is the column's, px");
  f.add_double("candidate-explored-px", &o.locations.explored_line_px,
               "CANDIDATES: a line this near the image of an explored object's axis (the request's explored places) "
               "is that object's, not among the --candidate-lines, px");
  f.add_double("cluster-radius", &o.locations.qt.radius, "CANDIDATES: QT cluster radius, m");
  f.add_double("cluster-min-fraction", &o.locations.qt.min_fraction, "CANDIDATES: smallest cluster, fraction of all");
  f.add_bool("stereo-check", &o.locations.stereo_check,
             "CANDIDATES and AXES: pair a left and a right line only if their support segments cover the same "
             "heights on the axis, from the table up; each line once per frame (busy tables, docs/clutter.md)");
  f.add_double("min-height-overlap", &o.locations.min_height_overlap,
               "CANDIDATES with --stereo-check: least overlap / union of the two lines' heights");
  f.add_double("max-foot-height", &o.locations.max_foot_height_m,
               "CANDIDATES with --stereo-check: lowest support end at most this far from the table, m");
  f.add_double("stereo-appearance", &o.locations.min_axis_colour_agreement,
               "CANDIDATES: pair a left and a right line only if both cameras' images show the same colour at "
               "this share of the heights along the axis (0: off; needs the camera images, docs/clutter.md)");
  f.add_double("appearance-tolerance", &o.locations.appearance.colour_tolerance,
               "CANDIDATES with --stereo-appearance: L1 BGR difference (0-765) of the same colour");
  f.add_double("appearance-waived-at-overlap", &o.locations.appearance_waived_at_overlap,
               "CANDIDATES with --stereo-appearance: support segments overlapping this much need no appearance "
               "check (above 1: never waived)");
  f.add_string("left-image-channel", &o.left_image_channel, "with --stereo-appearance: the left camera's images");
  f.add_string("right-image-channel", &o.right_image_channel, "with --stereo-appearance: the right camera's images");
}

void check(const Options& o) {
  if (o.calibration.empty()) throw FlagError("--calibration FILE is required");
  if (o.buffer < 1) throw FlagError("--buffer must be >= 1");
  if (o.lines < 0) throw FlagError("--lines must be >= 0");
  if (!(o.filter.max_tilt_deg >= 0 && o.filter.max_tilt_deg <= 90)) throw FlagError("--max-tilt must be in [0, 90]");
  if (!(o.filter.max_range_m > 0)) throw FlagError("--max-range must be > 0");
  if (!(o.triangulation.zmax > 0)) throw FlagError("--zmax must be > 0");
  if (o.triangulation.plane_samples < 0) throw FlagError("--plane-samples must be >= 0");
  if (!o.table_plane.empty()) plane_from_flag(o.table_plane);
  geo::LocationParams locations = o.locations;
  locations.max_range_m = o.filter.max_range_m;
  try {
    geo::validate(locations);
  } catch (const std::invalid_argument& e) {
    throw FlagError(e.what());
  }
}

}  // namespace

int main(int argc, char** argv) {
  return bus::guarded_main("triangulation", [&] {
    bus::Service service("triangulation",
                         "Stereo triangulation of symmetry lines into 3D axes (thesis sec. 4.3) and candidate\n"
                         "object locations on request (sec. 6.2).");
    Options opt;
    add_flags(service.flags(), opt);
    // CANDIDATES lie in the arm's workspace ring: the workspace file's, as the arm checks it.
    const robot::WorkspaceFlags workspace_flags(service.flags(), {"ring-inner", "ring-outer"}, "CANDIDATES: ");
    if (!service.parse(argc, argv)) return 0;
    const robot::Workspace workspace = workspace_flags.resolve();
    opt.locations.ring_inner_m = workspace.ring_inner;
    opt.locations.ring_outer_m = workspace.ring_outer;
    try {
      opt.locations.column_lines = geo::parse_column_lines(opt.column_lines);
    } catch (const std::invalid_argument& e) {
      throw FlagError(std::string("--candidate-column-lines: ") + e.what());
    }
    check(opt);
    opt.locations.max_range_m = opt.filter.max_range_m;
    Triangulation triangulation(service, opt);  // loads the rig: a bad file ends here, naming the field
    service.start();
    service.watch_heartbeats({"symmetry"});  // its input: say so when line detection goes quiet
    triangulation.subscribe();
    return service.run();
  });
}
