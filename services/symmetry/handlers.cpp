#include "handlers.hpp"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "nudge/bus/image.hpp"
#include "nudge/bus/symmetry_convert.hpp"
#include "nudge/contours_t.hpp"
#include "nudge/geometry/interesting_locations.hpp"
#include "nudge/geometry/self_mask.hpp"
#include "nudge/geometry/upright.hpp"
#include "nudge/log.hpp"
#include "nudge/timing.hpp"

namespace nudge::symmetry_service {

namespace {

// The contour of each of the first `count` lines, as a message (thesis sec. 4.2).
contours_t contours_message(const symmetry::EdgeSet& edges, const std::vector<symmetry::Line>& lines, int count,
                            const segmentation::Segmenter& segmenter, const image_t& image) {
  contours_t msg;
  msg.utime = image.utime;
  msg.frame_id = image.frame_id;
  msg.camera = image.camera;
  auto to_points = [](const std::vector<cv::Point2d>& side) {
    std::vector<std::vector<float>> out;
    for (const auto& p : side) out.push_back({static_cast<float>(p.x), static_cast<float>(p.y)});
    return out;
  };
  for (int i = 0; i < std::min<int>(count, static_cast<int>(lines.size())); ++i) {
    const segmentation::Contour c = segmenter.segment(edges, lines[i]);
    if (c.empty()) continue;
    object_contour_t oc;
    oc.line_index = i;
    oc.score = static_cast<float>(c.score);
    oc.left = to_points(c.left);
    oc.right = to_points(c.right);
    oc.num_left = static_cast<int32_t>(oc.left.size());
    oc.num_right = static_cast<int32_t>(oc.right.size());
    msg.contours.push_back(oc);
  }
  msg.num_contours = static_cast<int32_t>(msg.contours.size());
  return msg;
}

// Mirror-tolerant voting needs the edges' gradient orientations.
symmetry::EdgeParams edge_params_for(const Options& options) {
  symmetry::EdgeParams edge = options.edge;
  edge.gradients = options.params.mirror_tolerance_deg > 0 || edge.gradients;
  return edge;
}

// With the reach filter, the weak-peak cut (min_peak_ratio of the top peak) is made after it,
// against the top line standing within reach: the arm's base column, fully in view once the arm
// has withdrawn, outvotes a cup in front of it tenfold, and its peak, dropped by the reach filter,
// would otherwise have cut the cup's (held-out h01 cups, 2026-11-25).
symmetry::Params detector_params_for(const Options& options) {
  symmetry::Params params = options.params;
  if (options.reach) params.min_peak_ratio = 0;
  return params;
}

segmentation::SegmentParams segment_params_for(const Options& options) {
  segmentation::SegmentParams params;
  if (options.params.dmax > 0) params.max_width = options.params.dmax;  // thesis: MAXw is usually Dmax
  return params;
}

}  // namespace

Handlers::Handlers(bus::Service& service, const Options& options)
    : service_(service),
      options_(options),
      detector_(detector_params_for(options), edge_params_for(options)),
      segmenter_(segment_params_for(options)) {
  options_.edge = edge_params_for(options);
  for (const auto& channel : options_.inputs) {
    const std::string out = bus::channel::derived(channel, bus::channel::SYMMETRY);
    const std::string contours_out = bus::channel::derived(channel, bus::channel::CONTOURS);
    const bool needs_side = options_.upright || !options_.column_mask_left.empty() || options_.table_texture ||
                            options_.reach || options_.explored;
    const Output output{out, contours_out, needs_side ? side_of_channel(channel) : geometry::Side::Left};
    service_.subscriptions().subscribe<image_t>(channel, [this, output](const image_t& msg, const std::string&) {
      if (options_.table_texture)
        on_stereo_image(msg, output);
      else
        on_image(msg, output);
    });
    log::info() << channel << " -> " << out;
  }
  if (options_.explored)
    service_.subscriptions().subscribe<candidates_request_t>(
        bus::channel::CANDIDATES_REQUEST, [this](const candidates_request_t& m, const std::string&) { on_request(m); });
}

void Handlers::on_request(const candidates_request_t& request) {
  const Options::Explored& e = *options_.explored;
  const geometry::TableFrame frame(e.table, e.arm_base);
  std::vector<geometry::Column> columns;
  for (int i = 0; i < request.num_explored && i < static_cast<int>(request.explored.size()); ++i) {
    const Eigen::Vector3d place(request.explored[i][0], request.explored[i][1], request.explored[i][2]);
    if (!place.allFinite()) {
      log::warn() << bus::channel::CANDIDATES_REQUEST << " of " << request.utime << ": explored place " << i
                  << " is not finite; its edges are kept";
      continue;
    }
    columns.push_back({frame.to_camera(place), e.radius, e.height});
  }
  for (const geometry::Side side : {geometry::Side::Left, geometry::Side::Right})
    explored_mask_[side == geometry::Side::Left ? 0 : 1] =
        columns.empty() ? cv::Mat() : geometry::columns_mask(e.rig, side, e.table, columns, e.margin_px, e.band_px);
  if (!columns.empty()) log::info() << "survey: the edges of " << columns.size() << " explored object(s) left out";
}

geometry::Side side_of_channel(const std::string& channel) {
  auto ends_with = [&](const std::string& suffix) {
    return channel.size() >= suffix.size() && channel.compare(channel.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  if (ends_with("LEFT")) return geometry::Side::Left;
  if (ends_with("RIGHT")) return geometry::Side::Right;
  throw std::invalid_argument("input channel " + channel + " names no camera (LEFT or RIGHT at its end): the upright check, the column mask and the table "
                              "texture need one");
}

void Handlers::on_image(const image_t& msg, const Output& out) {
  const cv::Mat image = bus::to_mat(msg);  // throws ImageError naming the image: counted, skipped
  detect_and_publish(image, msg, out, cv::Mat());
}

void Handlers::on_stereo_image(const image_t& msg, const Output& out) {
  cv::Mat image = bus::to_mat(msg);  // throws ImageError naming the image: counted, skipped
  const Options::TableTexture& texture = *options_.table_texture;
  const geometry::PlaneWarp& warp = out.side == geometry::Side::Left ? texture.to_left : texture.to_right;
  if (image.size() != warp.size())
    throw std::runtime_error(out.lines + " frame " + std::to_string(msg.frame_id) + ": image " +
                             std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                             " differs from the table texture's calibration");
  image_t meta;  // what the lines message repeats, without the pixels
  meta.utime = msg.utime;
  meta.frame_id = msg.frame_id;
  meta.camera = msg.camera;
  const bool partner = held_ && held_->out.side != out.side &&
                       std::llabs(held_->meta.utime - msg.utime) <= texture.max_skew_us;
  if (!partner) {
    if (held_)
      log::debug() << held_->out.lines << " frame " << held_->meta.frame_id
                   << ": no image from the other camera within " << texture.max_skew_us << " us; dropped";
    held_ = Held{std::move(meta), image.clone(), out};  // to_mat may share the message's buffer
    return;
  }
  Held first = std::move(*held_);
  held_.reset();
  detect_and_publish(first.image, first.meta, first.out, image);
  detect_and_publish(image, meta, out, first.image);
}

void Handlers::detect_and_publish(const cv::Mat& image, const image_t& msg, const Output& output, const cv::Mat& other) {
  const std::string& out = output.lines;
  const geometry::Side side = output.side;
  Stopwatch watch;
  symmetry::EdgeSet edges = symmetry::detect_edges(image, options_.edge);
  const cv::Mat& column = side == geometry::Side::Left ? options_.column_mask_left : options_.column_mask_right;
  if (!column.empty()) {
    if (column.size() != image.size())
      throw std::runtime_error(out + " frame " + std::to_string(msg.frame_id) + ": image " + std::to_string(image.cols) +
                               "x" + std::to_string(image.rows) + " differs from the column mask's calibration");
    symmetry::remove_edges(edges, column);
  }
  const cv::Mat& explored = explored_mask_[side == geometry::Side::Left ? 0 : 1];
  if (!explored.empty()) {
    if (explored.size() != image.size())
      throw std::runtime_error(out + " frame " + std::to_string(msg.frame_id) + ": image " + std::to_string(image.cols) +
                               "x" + std::to_string(image.rows) + " differs from the explored objects' calibration");
    symmetry::remove_edges(edges, explored);
  }
  if (!other.empty()) {
    const Options::TableTexture& texture = *options_.table_texture;
    const geometry::PlaneWarp& warp = side == geometry::Side::Left ? texture.to_left : texture.to_right;
    symmetry::remove_edges(edges, geometry::table_texture_mask(image, other, warp, texture.params));
  }
  const double edges_ms = watch.elapsed_ms();
  symmetry::Result result = detector_.detect(edges);
  result.ms.edges_ms = edges_ms;
  if (options_.reach) {  // part of finding the peaks
    Stopwatch reach_watch;
    const Options::Reach& reach = *options_.reach;
    result.lines = geometry::lines_standing_within(reach.rig, side, reach.table, reach.centre, reach.radius, result.lines,
                                                      reach.inner_radius);
    // A line leaning far from the image of an upright axis is the table's or the wall's clutter, or
    // lies between two objects: the survey pairs none of them, and kept they take the places of the
    // weaker lines of objects still to find (held-out hm2: four of the left camera's five).
    if (reach.max_tilt_deg > 0)
      result.lines = geometry::upright_lines(reach.rig, side, reach.table, result.lines, reach.max_tilt_deg);
    symmetry::drop_weak_lines(result.lines, options_.params.min_peak_ratio);
    if (reach.one_per_place_px > 0)
      result.lines = symmetry::one_line_per_place_first(result.lines, reach.one_per_place_px);
    if (reach.keep > 0 && reach.column_px > 0)
      result.lines = geometry::first_lines_column_uncounted(reach.rig, side, reach.table, result.lines, reach.keep,
                                                            geometry::TableFrame(reach.table, reach.centre).origin(),
                                                            reach.column_px);
    else if (reach.keep > 0 && static_cast<int>(result.lines.size()) > reach.keep)
      result.lines.resize(reach.keep);
    result.ms.peaks_ms += reach_watch.elapsed_ms();
  }
  if (options_.verify) {  // part of finding the peaks
    Stopwatch verify_watch;
    if (options_.upright) {
      const Options::Upright& u = *options_.upright;
      if (image.cols != (side == geometry::Side::Left ? u.rig.left : u.rig.right).width ||
          image.rows != (side == geometry::Side::Left ? u.rig.left : u.rig.right).height)
        throw std::runtime_error(out + " frame " + std::to_string(msg.frame_id) + ": image " + std::to_string(image.cols) +
                                 "x" + std::to_string(image.rows) + " differs from the calibration's camera");
      result.lines = geometry::upright_lines(u.rig, side, u.table, result.lines, u.max_tilt_deg);
    }
    result.lines = symmetry::verify_lines(detector_, edges, image, result.lines, options_.verify_params);
    result.ms.peaks_ms += verify_watch.elapsed_ms();
  }
  service_.publish(out, bus::to_message(result, msg.utime, msg.frame_id, msg.camera));
  if (options_.contours > 0)
    service_.publish(output.contours, contours_message(edges, result.lines, options_.contours, segmenter_, msg));
  log::debug() << out << " frame " << msg.frame_id << ": " << result.lines.size() << " lines, " << result.num_edges
                << " edges, " << result.ms.total_ms() << " ms";
}

}  // namespace nudge::symmetry_service
