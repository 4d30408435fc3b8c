#pragma once
// The symmetry service's message handlers, apart from main() so that tests build them on an
// in-process bus (docs/architecture.md, "Testing a service's handlers in one process").
#include <optional>
#include <string>
#include <vector>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/candidates_request_t.hpp"
#include "nudge/image_t.hpp"
#include "nudge/segmentation/segment.hpp"
#include "nudge/symmetry/detector.hpp"
#include "nudge/geometry/plane.hpp"
#include "nudge/geometry/stereo_pairing.hpp"
#include "nudge/geometry/stereo_rig.hpp"
#include "nudge/geometry/table_texture.hpp"
#include "nudge/symmetry/verify.hpp"

namespace nudge::symmetry_service {

struct Options {
  symmetry::Params params;
  symmetry::EdgeParams edge;
  std::vector<std::string> inputs = {bus::channel::CAMERA_LEFT, bus::channel::CAMERA_RIGHT};
  int contours = 0;  // also segment the contours of the top N lines; 0: off
  // Busy tables (issue 14, docs/clutter.md): verify the params.num_lines peaks (local support,
  // mirrored colour) and publish the best verify.keep of them; off unless `verify` is set.
  bool verify = false;
  symmetry::VerifyParams verify_params;
  // With verify: only the peaks that can be the image of an axis standing upright on the table
  // are verified (geometry/upright.hpp); needs the rig and the table, and input channels that
  // name their camera (..._LEFT, ..._RIGHT).
  struct Upright {
    geometry::StereoRig rig;
    geometry::Plane table;  // right camera frame
    double max_tilt_deg = 2;
  };
  std::optional<Upright> upright;
  // The arm's base column left out of the edges (geometry/self_mask.hpp): one mask per camera,
  // the calibration's image size; input channels must name their camera. Empty: off.
  cv::Mat column_mask_left, column_mask_right;
  // The table's own texture left out of the edges (geometry/table_texture.hpp): each image is
  // compared with the other camera's image of the same moment through the table plane. Needs one
  // input channel per camera (..._LEFT and ..._RIGHT); an image is handled when its partner (the
  // other camera's, within max_skew_us) has come, and one whose partner never comes is dropped.
  struct TableTexture {
    geometry::PlaneWarp to_left, to_right;
    geometry::TableTextureParams params;
    int64_t max_skew_us = 20000;
  };
  std::optional<TableTexture> table_texture;
  // Only lines standing within reach (geometry/upright.hpp, lines_standing_within): of the
  // params.num_lines peaks, those whose support segment stands on the table within `radius` of
  // `centre` (right camera frame) and not within `inner_radius` of it (the arm's base column), the
  // first `keep` of them (0: all). With column_px > 0 a line within column_px of the image of the
  // arm's base column (the upright axis at `centre`'s foot on the table) rides along without
  // counting among the `keep` (geometry::first_lines_column_uncounted): the column, always in
  // view, would otherwise take one of the places in every image. Needs the channels' cameras.
  struct Reach {
    geometry::StereoRig rig;
    geometry::Plane table;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    double radius = 0.45;
    double inner_radius = 0.0;
    int keep = 0;
    double column_px = 0;
    double max_tilt_deg = 0;  // > 0: drop lines that cannot be an upright axis's image before the keep
    // > 0: before the keep, each place in the image offered once before any twice
    // (symmetry::one_line_per_place_first): lines within this many pixels of a stronger one wait.
    double one_per_place_px = 0;
  };
  std::optional<Reach> reach;
  // Objects already explored left out of the edges (geometry::columns_mask): each
  // CANDIDATES_REQUEST names the places of the objects a survey has explored and that still
  // stand (table frame); from then on, until the next request, each is taken as an upright
  // cylinder of `radius` and `height` there and its image region (band_px 0) or its outline's
  // band (band_px either side) leaves each camera's edges. Their own lines, and the phantoms
  // their edges make with a neighbour's, then no longer take the places of the objects still to
  // find. Needs the channels' cameras; the image must be the calibration's size.
  struct Explored {
    geometry::StereoRig rig;
    geometry::Plane table;
    Eigen::Vector3d arm_base = Eigen::Vector3d::Zero();  // right camera frame: the table frame's origin
    double radius = 0.05;
    double height = 0.25;
    int margin_px = 4;
    int band_px = 0;
  };
  std::optional<Explored> explored;
};

// The camera of an input channel for the upright check: LEFT or RIGHT at the end of its name.
// Throws std::invalid_argument naming a channel that says neither.
geometry::Side side_of_channel(const std::string& channel);

// Subscribes the started `service` to every input channel: each image's symmetry lines go out on
// its SYMMETRY_* channel, with Options::contours > 0 also the contours on CONTOURS_*. A bad image
// is reported naming it, counted and skipped. Holds the detector: keep it while handling.
class Handlers {
 public:
  Handlers(bus::Service& service, const Options& options);
  Handlers(const Handlers&) = delete;
  Handlers& operator=(const Handlers&) = delete;

 private:
  struct Output {
    std::string lines, contours;
    geometry::Side side = geometry::Side::Left;
  };
  void on_image(const image_t& msg, const Output& out);
  // With Options::explored: the masks of the request's explored places.
  void on_request(const candidates_request_t& request);
  // With Options::table_texture: holds an image until the other camera's partner comes.
  void on_stereo_image(const image_t& msg, const Output& out);
  // Detects and publishes. `other`: the other camera's image of the same moment, whose agreement
  // through the table plane marks the table's texture (empty: no table texture check).
  void detect_and_publish(const cv::Mat& image, const image_t& meta, const Output& out, const cv::Mat& other);

  struct Held {
    image_t meta;  // without its pixels
    cv::Mat image;
    Output out;
  };
  std::optional<Held> held_;
  cv::Mat explored_mask_[2];  // left, right; empty: nothing explored

  bus::Service& service_;
  Options options_;
  symmetry::Detector detector_;
  segmentation::Segmenter segmenter_;
};

}  // namespace nudge::symmetry_service
