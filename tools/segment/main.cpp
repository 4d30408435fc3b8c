// nudge-segment: symmetry-guided contour segmentation of photographs (thesis sec. 4.2, fig. 4.3/4.4).
// Detects the symmetry lines, segments the object contour about each of the strongest ones, prints
// one JSON object per image and optionally draws the contours over the edge image.
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <iostream>

#include "nudge/flags.hpp"
#include "nudge/json.hpp"
#include "nudge/log.hpp"
#include "nudge/segmentation/segment.hpp"
#include "nudge/symmetry/detector.hpp"
#include "nudge/timing.hpp"

using namespace nudge;
namespace sym = nudge::symmetry;
namespace seg = nudge::segmentation;

namespace {

struct Options {
  sym::Params params;
  seg::SegmentParams segment;
  std::vector<double> canny;
  std::string draw;
  double blur = -1, dmin = -1, dmax = -1, max_width = -1;
};

// "out.png" -> "out_3.png" when several images are processed.
std::string numbered(const std::string& path, size_t index, size_t count) {
  if (count <= 1) return path;
  const auto dot = path.rfind('.');
  const std::string stem = dot == std::string::npos ? path : path.substr(0, dot);
  const std::string ext = dot == std::string::npos ? ".png" : path.substr(dot);
  return stem + "_" + std::to_string(index + 1) + ext;
}

// Defaults that scale with the photograph, as nudge-detect's (the thesis' 25/250 px and blur 1 at
// 640x480); MAXw follows Dmax ("usually set to Dmax", sec. 4.2.2).
void fill_image_defaults(const cv::Mat& image, const Options& opt, sym::Params* p, sym::EdgeParams* e,
                         seg::SegmentParams* s) {
  const double short_side = std::min(image.cols, image.rows), long_side = std::max(image.cols, image.rows);
  *p = opt.params;
  p->dmin = opt.dmin >= 0 ? opt.dmin : std::max(5.0, 0.05 * short_side);
  p->dmax = opt.dmax >= 0 ? opt.dmax : 0.5 * long_side;
  e->blur_sigma = opt.blur >= 0 ? opt.blur : std::max(1.0, short_side / 480.0);
  e->auto_canny = opt.canny.size() != 2;
  if (!e->auto_canny) {
    e->canny_low = opt.canny[0];
    e->canny_high = opt.canny[1];
  }
  *s = opt.segment;
  s->max_width = opt.max_width > 0 ? opt.max_width : p->dmax > 0 ? p->dmax : long_side;
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
  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  if (image.empty()) {
    log::error() << path << ": cannot read the image (missing, unreadable or not an image)";
    return false;
  }
  sym::Params p;
  sym::EdgeParams e;
  seg::SegmentParams s;
  fill_image_defaults(image, opt, &p, &e, &s);
  Stopwatch watch;
  cv::Mat edge_image;
  const sym::EdgeSet edges = sym::detect_edges(image, e, &edge_image);
  const double edges_ms = watch.lap_ms();
  const sym::Result result = sym::Detector(p, e).detect(edges);
  watch.restart();
  const seg::Segmenter segmenter(s);
  std::vector<Segmented> found;
  for (const sym::Line& line : result.lines) found.push_back({line, segmenter.segment(edges, line)});
  const double segment_ms = watch.elapsed_ms();
  std::cout << json_for(path, result, found, edges_ms, segment_ms, s) << std::endl;

  if (!opt.draw.empty()) {
    cv::Mat picture = edge_image;
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
  opt.params.num_lines = 3;
  Flags flags("nudge-segment",
              "Segments object contours about their symmetry lines (Li 2008, sec. 4.2) and prints one JSON\n"
              "object per image: {image, width, height, edges, contours: [{line: {r, theta_deg, votes},\n"
              "score, cells, left: [[x, y]...], right: [[x, y]...]}], ms}. Contour sides run along the line.\n"
              "Detection defaults scale with the image as nudge-detect's; MAXw defaults to Dmax.");
  flags.set_positional("IMAGE...", "image files");
  flags.add_int("lines", &opt.params.num_lines, "symmetry lines per image to segment (strongest first)");
  flags.add_double("dmin", &opt.dmin, "minimum pairing distance, px (default: scaled)");
  flags.add_double("dmax", &opt.dmax, "maximum pairing distance, px; 0 = none (default: scaled)");
  flags.add_double("theta-min", &opt.params.theta_min_deg, "orientation limit, degrees");
  flags.add_double("theta-max", &opt.params.theta_max_deg, "orientation limit, degrees (min > max wraps)");
  flags.add_doubles("canny", &opt.canny, 2, "Canny thresholds LOW HIGH (default: from the image)");
  flags.add_double("blur", &opt.blur, "Gaussian blur sigma before Canny; 0 = none (default: scaled)");
  flags.add_double("max-width", &opt.max_width, "MAXw: widest edge pair in the SEPT, px (default: Dmax)");
  flags.add_double("max-mid", &opt.segment.max_mid, "MAXmid: largest midpoint deviation, px");
  flags.add_string("draw", &opt.draw, "write the edge image with the lines and contours to this PNG");
  try {
    if (!flags.parse(argc, argv)) return 0;
    sym::Params check = opt.params;
    check.dmin = std::max(0.0, opt.dmin);
    check.dmax = opt.dmax >= 0 ? opt.dmax : 0;
    sym::validate(check);
    if (opt.canny.size() == 2) sym::validate(sym::EdgeParams{0, opt.canny[0], opt.canny[1], false});
    if (opt.blur > 50) throw FlagError("--blur must be in [0, 50]");
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
  bool all_ok = true;
  const auto& images = flags.positional();
  for (size_t i = 0; i < images.size(); ++i) {
    try {
      all_ok &= process(images[i], i, images.size(), opt);
    } catch (const std::exception& e) {
      log::error() << images[i] << ": " << e.what();
      all_ok = false;
    }
  }
  return all_ok ? 0 : 1;
}
