// nudge-segment: symmetry-guided contour segmentation of photographs (thesis sec. 4.2, fig. 4.3/4.4).
// Detects the symmetry lines, segments the object contour about each of the strongest ones, prints
// one JSON object per image and optionally draws the contours over the edge image.
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <iostream>

#include "nudge/camera/image_file.hpp"
#include "nudge/flags.hpp"
#include "nudge/json.hpp"
#include "nudge/log.hpp"
#include "nudge/segmentation/segment.hpp"
#include "nudge/symmetry/detector.hpp"
#include "nudge/timing.hpp"
#include "../common/photo_tool.hpp"

using namespace nudge;
namespace sym = nudge::symmetry;
namespace seg = nudge::segmentation;
using nudge::tools::numbered;

namespace {

struct Options {
  sym::PhotoOptions photo;
  seg::SegmentParams segment;
  std::string draw;
  double max_width = -1;
};

// MAXw follows Dmax ("usually set to Dmax", sec. 4.2.2), at the working size.
seg::SegmentParams segment_params(const Options& opt, const sym::PhotoDetection& found) {
  seg::SegmentParams s = opt.segment;
  const double long_side = std::max(found.working_image.cols, found.working_image.rows);
  s.max_width = opt.max_width > 0 ? opt.max_width : found.params.dmax > 0 ? found.params.dmax : long_side;
  return s;
}

// Contour points from the working size back to the photograph's pixels.
std::vector<cv::Point2d> to_image(const std::vector<cv::Point2d>& points, cv::Size from, cv::Size to) {
  std::vector<cv::Point2d> out;
  for (const auto& p : points)
    out.emplace_back((p.x + 0.5) * to.width / from.width - 0.5, (p.y + 0.5) * to.height / from.height - 0.5);
  return out;
}

const cv::Scalar kColours[] = {{0, 0, 255}, {0, 200, 0}, {255, 80, 0}, {255, 0, 255}, {0, 160, 255}, {255, 255, 0}};

struct Segmented {
  sym::Line line;
  seg::Contour contour;
};

void write_points(JsonWriter& j, const std::string& key, const std::vector<cv::Point2d>& points) {
  j.key(key).begin_array();
  for (const auto& p : points) {
    j.begin_array();
    j.value(std::round(p.x * 100) / 100).value(std::round(p.y * 100) / 100);
    j.end_array();
  }
  j.end_array();
}

std::string json_for(const std::string& path, const sym::Result& r, const std::vector<Segmented>& found,
                     double edges_ms, double segment_ms, const seg::SegmentParams& s) {
  JsonWriter j;
  j.begin_object();
  j.field("image", path).field("width", r.width).field("height", r.height).field("edges", r.num_edges);
  j.key("contours").begin_array();
  for (const Segmented& f : found) {
    j.begin_object();
    j.key("line").begin_object();
    j.field("r", f.line.r).field("theta_deg", f.line.theta * 180.0 / M_PI).field("votes", f.line.votes);
    j.end_object();
    j.field("score", f.contour.score).field("cells", static_cast<int>(f.contour.cells.size()));
    write_points(j, "left", f.contour.left);
    write_points(j, "right", f.contour.right);
    j.end_object();
  }
  j.end_array();
  j.key("ms").begin_object();
  j.field("edges", edges_ms).field("detect", r.ms.vote_ms + r.ms.peaks_ms).field("segment", segment_ms);
  j.end_object();
  j.key("params").begin_object();
  j.field("max_width", s.max_width).field("max_mid", s.max_mid);
  j.end_object();
  j.end_object();
  return j.str();
}

bool process(const std::string& path, size_t index, size_t count, const Options& opt) {
  cv::Mat image;
  try {
    image = camera::read_image_file(path, cv::IMREAD_COLOR);  // refuses truncated and oversized files
  } catch (const camera::ImageFileError& e) {
    log::error() << e.what();
    return false;
  }
  const sym::PhotoDetection detected = sym::detect_photo(image, opt.photo);
  const seg::SegmentParams s = segment_params(opt, detected);
  Stopwatch watch;
  const seg::Segmenter segmenter(s);
  std::vector<Segmented> at_work;
  for (const sym::Line& line : detected.at_working_size.lines) at_work.push_back({line, segmenter.segment(detected.edges, line)});
  const double segment_ms = watch.elapsed_ms();
  // Report in the photograph's coordinates.
  std::vector<Segmented> found = at_work;
  for (size_t i = 0; i < found.size(); ++i) {
    found[i].line = detected.in_image.lines[i];
    found[i].contour.left = to_image(at_work[i].contour.left, detected.working_image.size(), image.size());
    found[i].contour.right = to_image(at_work[i].contour.right, detected.working_image.size(), image.size());
  }
  std::cout << json_for(path, detected.in_image, found, detected.in_image.ms.edges_ms, segment_ms, s) << std::endl;

  if (!opt.draw.empty()) {  // at the photograph's size, over the edges scaled up from the working size
    cv::Mat picture = tools::at_size(detected.edge_image, image.size());
    for (size_t i = 0; i < found.size(); ++i)
      picture = seg::draw_contour(picture, found[i].contour, found[i].line, kColours[i % std::size(kColours)]);
    const std::string out = numbered(opt.draw, index, count);
    if (!cv::imwrite(out, picture)) throw std::runtime_error("cannot write " + out);
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  log::set_component("segment");
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);  // we report bad files ourselves
  Options opt;
  opt.photo.params.num_lines = 3;
  Flags flags("nudge-segment",
              "Segments object contours about their symmetry lines (Li 2008, sec. 4.2) and prints one JSON\n"
              "object per image: {image, width, height, edges, contours: [{line: {r, theta_deg, votes},\n"
              "score, cells, left: [[x, y]...], right: [[x, y]...]}], ms}. Contour sides run along the line.\n"
              "Detection defaults scale with the image as nudge-detect's; MAXw defaults to Dmax.");
  flags.set_positional("IMAGE...", "image files");
  tools::add_photo_flags(flags, &opt.photo);
  flags.add_double("max-width", &opt.max_width, "MAXw: widest edge pair in the SEPT, px (default: Dmax)");
  flags.add_double("max-mid", &opt.segment.max_mid, "MAXmid: largest midpoint deviation, px");
  flags.add_string("draw", &opt.draw, "write the edge image with the lines and contours to this PNG");
  try {
    if (!flags.parse(argc, argv)) return 0;
    tools::validate_photo_options(opt.photo);
    seg::SegmentParams seg_check = opt.segment;
    if (opt.max_width > 0) seg_check.max_width = opt.max_width;
    seg::validate(seg_check);
  } catch (const std::exception& e) {
    std::cerr << "nudge-segment: " << e.what() << "\n";
    return 2;
  }
  if (flags.positional().empty()) {
    std::cerr << flags.help();
    return 2;
  }
  return tools::run_on_images(flags.positional(), [&](const std::string& path, size_t index, size_t count) {
    return process(path, index, count, opt);
  });
}
