// symmetry: detects bilateral symmetry lines in every image on its input channels and publishes
// them on the matching SYMMETRY_* channel (CAMERA_LEFT -> SYMMETRY_LEFT, CAMERA -> SYMMETRY); with
// --contours N also the object contours of the top N lines on CONTOURS_* (thesis sec. 4.2).
#include <sstream>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/bus/symmetry_convert.hpp"
#include "nudge/contours_t.hpp"
#include "nudge/image_t.hpp"
#include "nudge/log.hpp"
#include "nudge/timing.hpp"
#include "nudge/segmentation/segment.hpp"
#include "nudge/symmetry/detector.hpp"

using namespace nudge;

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

}  // namespace

int main(int argc, char** argv) {
  return bus::guarded_main("symmetry", [&] {
    bus::Service service("symmetry", "Fast bilateral symmetry detection (thesis ch. 3) on camera images.");
    symmetry::Params params;
    symmetry::EdgeParams edge;
    edge.blur_sigma = 1.0;  // thesis: Gaussian blur first on camera images
    std::string inputs = std::string(bus::channel::CAMERA_LEFT) + "," + bus::channel::CAMERA_RIGHT;
    std::vector<double> canny = {edge.canny_low, edge.canny_high};
    auto& f = service.flags();
    f.add_string("inputs", &inputs, "comma-separated image channels");
    f.add_int("lines", &params.num_lines, "symmetry lines per image (Nlines)");
    f.add_double("dmin", &params.dmin, "minimum pairing distance, px");
    f.add_double("dmax", &params.dmax, "maximum pairing distance, px (0: none)");
    f.add_double("theta-min", &params.theta_min_deg, "orientation limit, degrees");
    f.add_double("theta-max", &params.theta_max_deg, "orientation limit, degrees");
    f.add_doubles("canny", &canny, 2, "Canny thresholds LOW HIGH");
    f.add_double("blur", &edge.blur_sigma, "Gaussian blur sigma before Canny (0: none)");
    f.add_double("min-peak-ratio", &params.min_peak_ratio, "drop peaks below this fraction of the top one");
    f.add_bool("once-per-row", &params.once_per_row, "a row of Rot increments a bin at most once");
    f.add_int("max-row-pixels", &params.max_row_pixels, "skip rows of Rot with more pixels (0: off)");
    f.add_double("mirror-tolerance", &params.mirror_tolerance_deg,
                 "pairs vote only if their edge orientations mirror about the axis within DEG (0: off)");
    f.add_int("threads", &params.threads, "threads across angles");
    int contours = 0;
    f.add_int("contours", &contours, "also segment the contours of the top N lines (CONTOURS_*); 0: off");
    if (!service.parse(argc, argv)) return 0;
    edge.canny_low = canny[0];
    edge.canny_high = canny[1];
    try {
      symmetry::validate(params);
      symmetry::validate(edge);
    } catch (const std::invalid_argument& e) {
      throw FlagError(e.what());
    }
    if (contours < 0) throw FlagError("--contours must be >= 0");
    edge.gradients = params.mirror_tolerance_deg > 0;
    symmetry::Detector detector(params, edge);
    segmentation::SegmentParams segment_params;
    if (params.dmax > 0) segment_params.max_width = params.dmax;  // thesis: MAXw is usually Dmax
    const segmentation::Segmenter segmenter(segment_params);
    service.start();
    for (const auto& channel : split_list(inputs)) {
      const std::string out = bus::channel::derived(channel, bus::channel::SYMMETRY);
      const std::string contours_out = bus::channel::derived(channel, bus::channel::CONTOURS);
      service.subscriptions().subscribe<image_t>(channel, [&, out, contours_out](const image_t& msg, const std::string&) {
        const cv::Mat image = bus::to_mat(msg);  // throws ImageError naming the image: counted, skipped
        Stopwatch watch;
        const symmetry::EdgeSet edges = symmetry::detect_edges(image, edge);
        const double edges_ms = watch.elapsed_ms();
        symmetry::Result result = detector.detect(edges);
        result.ms.edges_ms = edges_ms;
        service.publish(out, bus::to_message(result, msg.utime, msg.frame_id, msg.camera));
        if (contours > 0) service.publish(contours_out, contours_message(edges, result.lines, contours, segmenter, msg));
        log::debug() << out << " frame " << msg.frame_id << ": " << result.lines.size() << " lines, "
                     << result.num_edges << " edges, " << result.ms.total_ms() << " ms";
      });
      log::info() << channel << " -> " << out;
    }
    return service.run();
  });
}
