// nudge-detect: bilateral symmetry lines of photographs, one JSON object per image on stdout.
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <iostream>
#include <sstream>

#include "nudge/camera/image_file.hpp"
#include "nudge/flags.hpp"
#include "nudge/json.hpp"
#include "nudge/log.hpp"
#include "nudge/symmetry/detector.hpp"
#include "nudge/symmetry/photo.hpp"
#include "nudge/timing.hpp"
#include "../common/photo_tool.hpp"

using namespace nudge;
using nudge::tools::numbered;
namespace sym = nudge::symmetry;

namespace {

struct Options {
  sym::PhotoOptions photo;
  std::string draw, accumulator, voters, edges_out, skew;
  int voters_line = 1;
};

void write_image(const std::string& path, const cv::Mat& image) {
  if (!cv::imwrite(path, image)) throw std::runtime_error("cannot write " + path);
}

std::string json_for(const std::string& path, const sym::Result& r, const sym::Params& p,
                     const sym::EdgeParams& e) {
  JsonWriter j;
  j.begin_object();
  j.field("image", path).field("width", r.width).field("height", r.height).field("edges", r.num_edges);
  j.key("lines").begin_array();
  for (const auto& l : r.lines) {
    j.begin_object();
    j.field("r", l.r).field("theta_deg", l.theta * 180.0 / M_PI).field("votes", l.votes);
    j.field("x1", l.end1.x).field("y1", l.end1.y).field("x2", l.end2.x).field("y2", l.end2.y);
    j.field("seg_x1", l.seg1.x).field("seg_y1", l.seg1.y).field("seg_x2", l.seg2.x).field("seg_y2", l.seg2.y);
    if (l.skew != 0) j.field("skew_deg", l.skew * 180.0 / M_PI);
    j.end_object();
  }
  j.end_array();
  j.key("ms").begin_object();
  j.field("edges", r.ms.edges_ms).field("vote", r.ms.vote_ms).field("peaks", r.ms.peaks_ms);
  j.end_object();
  j.key("params").begin_object();
  j.field("dmin", p.dmin).field("dmax", p.dmax).field("theta_min", p.theta_min_deg).field("theta_max", p.theta_max_deg);
  j.field("blur", e.blur_sigma);
  if (!e.auto_canny) j.field("canny_low", e.canny_low).field("canny_high", e.canny_high);
  else j.field("canny", "auto");
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
  const sym::PhotoDetection found = sym::detect_photo(image, opt.photo);
  std::cout << json_for(path, found.in_image, found.params, found.edge_params) << std::endl;
  // Lines and edges are drawn at the photograph's size (edges scaled up from the working size).
  const cv::Mat edges_full = tools::at_size(found.edge_image, image.size());
  if (!opt.draw.empty()) write_image(numbered(opt.draw, index, count), sym::draw_lines(edges_full, found.in_image.lines));
  if (!opt.edges_out.empty()) write_image(numbered(opt.edges_out, index, count), edges_full);
  const auto& lines = found.at_working_size.lines;  // the voters live at the working size
  if (!opt.accumulator.empty()) {
    sym::Detector detector(found.params, found.edge_params);
    write_image(numbered(opt.accumulator, index, count), sym::accumulator_image(detector.vote(found.edges)));
  }
  if (!opt.voters.empty() && opt.voters_line >= 1 && opt.voters_line <= static_cast<int>(lines.size())) {
    const sym::Line& line = lines[opt.voters_line - 1];
    sym::Detector detector(found.params, found.edge_params);
    write_image(numbered(opt.voters, index, count),
                sym::draw_voting_pairs(found.edge_image, detector.voting_pairs(found.edges, line), line));
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  log::set_component("detect");
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);  // we report bad files ourselves
  Options opt;
  Flags flags("nudge-detect",
              "Detects bilateral symmetry lines (Li 2008, Algorithm 1) and prints one JSON object per image.\n"
              "Lines are (r px, theta deg) about the image centre; theta = 0 is vertical.\n"
              "Images larger than --max-side are detected on a scaled copy and the lines mapped back.\n"
              "Defaults scale with the image: dmin 5% of the short side, dmax 50% of the long side,\n"
              "blur sigma max(1, short side / 480), Canny thresholds from the image's gradients.");
  flags.set_positional("IMAGE...", "image files");
  tools::add_photo_flags(flags, &opt.photo);
  flags.add_bool("anti-alias", &opt.photo.params.anti_alias, "3x3 Gaussian vote kernel");
  flags.add_string("skew", &opt.skew, "skew angles to try, degrees, comma-separated (e.g. -20,-10,10,20)");
  flags.add_int("threads", &opt.photo.params.threads, "threads across angles");
  flags.add_string("draw", &opt.draw, "write the edges with the detected lines to this PNG");
  flags.add_string("edges", &opt.edges_out, "write the Canny edge image to this PNG");
  flags.add_string("accumulator", &opt.accumulator, "write the Hough accumulator (theta across, R down)");
  flags.add_string("voters", &opt.voters, "write the edge pairs that voted for line --voters-line");
  flags.add_int("voters-line", &opt.voters_line, "which line (1 = strongest) --voters shows");
  try {
    if (!flags.parse(argc, argv)) return 0;
    for (const auto& item : split_list(opt.skew)) opt.photo.params.skew_deg.push_back(parse_double(item, "--skew"));
    tools::validate_photo_options(opt.photo);
  } catch (const std::exception& e) {
    std::cerr << "nudge-detect: " << e.what() << "\n";
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
