// nudge-detect: bilateral symmetry lines of photographs, one JSON object per image on stdout.
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <iostream>
#include <sstream>

#include "nudge/flags.hpp"
#include "nudge/json.hpp"
#include "nudge/log.hpp"
#include "nudge/symmetry/detector.hpp"
#include "nudge/symmetry/photo.hpp"
#include "nudge/timing.hpp"

using namespace nudge;
namespace sym = nudge::symmetry;

namespace {

struct Options {
  sym::PhotoOptions photo;
  std::string draw, accumulator, voters, edges_out, skew;
  int voters_line = 1;
};

// "out.png" -> "out_3.png" when several images are processed.
std::string numbered(const std::string& path, size_t index, size_t count) {
  if (count <= 1) return path;
  const auto dot = path.rfind('.');
  const std::string stem = dot == std::string::npos ? path : path.substr(0, dot);
  const std::string ext = dot == std::string::npos ? ".png" : path.substr(dot);
  return stem + "_" + std::to_string(index + 1) + ext;
}

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
  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  if (image.empty()) {
    log::error() << path << ": cannot read the image (missing, unreadable or not an image)";
    return false;
  }
  const sym::PhotoDetection found = sym::detect_photo(image, opt.photo);
  std::cout << json_for(path, found.in_image, found.params, found.edge_params) << std::endl;
  // Pictures are drawn at the working size, where the edges live.
  const auto& lines = found.at_working_size.lines;
  if (!opt.draw.empty()) write_image(numbered(opt.draw, index, count), sym::draw_lines(found.edge_image, lines));
  if (!opt.edges_out.empty()) write_image(numbered(opt.edges_out, index, count), found.edge_image);
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
  flags.add_int("lines", &opt.photo.params.num_lines, "symmetry lines per image (Nlines)");
  flags.add_double("dmin", &opt.photo.dmin, "minimum pairing distance, px (default: scaled)");
  flags.add_double("dmax", &opt.photo.dmax, "maximum pairing distance, px; 0 = none (default: scaled)");
  flags.add_double("theta-min", &opt.photo.params.theta_min_deg, "orientation limit, degrees");
  flags.add_double("theta-max", &opt.photo.params.theta_max_deg, "orientation limit, degrees (min > max wraps)");
  flags.add_doubles("canny", &opt.photo.canny, 2, "Canny thresholds LOW HIGH (default: from the image)");
  flags.add_double("blur", &opt.photo.blur, "Gaussian blur sigma before Canny; 0 = none (default: scaled)");
  flags.add_double("min-peak-ratio", &opt.photo.params.min_peak_ratio, "drop peaks below this fraction of the top");
  flags.add_int("suppress-r", &opt.photo.params.suppress_r, "non-maximum suppression half-size in R, px");
  flags.add_int("suppress-theta", &opt.photo.params.suppress_theta, "non-maximum suppression half-size, deg");
  flags.add_bool("once-per-row", &opt.photo.params.once_per_row, "a row of Rot increments a bin at most once");
  flags.add_int("max-row-pixels", &opt.photo.params.max_row_pixels, "skip rows of Rot with more pixels (0: off)");
  flags.add_bool("anti-alias", &opt.photo.params.anti_alias, "3x3 Gaussian vote kernel");
  flags.add_string("skew", &opt.skew, "skew angles to try, degrees, comma-separated (e.g. -20,-10,10,20)");
  flags.add_int("threads", &opt.photo.params.threads, "threads across angles");
  flags.add_int("max-side", &opt.photo.max_side, "detect on a copy scaled to this long side, px (0: full size)");
  flags.add_string("draw", &opt.draw, "write the edges with the detected lines to this PNG");
  flags.add_string("edges", &opt.edges_out, "write the Canny edge image to this PNG");
  flags.add_string("accumulator", &opt.accumulator, "write the Hough accumulator (theta across, R down)");
  flags.add_string("voters", &opt.voters, "write the edge pairs that voted for line --voters-line");
  flags.add_int("voters-line", &opt.voters_line, "which line (1 = strongest) --voters shows");
  try {
    if (!flags.parse(argc, argv)) return 0;
    std::stringstream ss(opt.skew);
    for (std::string item; std::getline(ss, item, ',');)
      if (!item.empty()) opt.photo.params.skew_deg.push_back(parse_double(item, "--skew"));
    sym::Params check = opt.photo.params;
    check.dmin = std::max(0.0, opt.photo.dmin);
    check.dmax = opt.photo.dmax >= 0 ? opt.photo.dmax : 0;
    sym::validate(check);
    if (opt.photo.canny.size() == 2) sym::validate(sym::EdgeParams{0, opt.photo.canny[0], opt.photo.canny[1], false});
    if (opt.photo.blur > 50) throw FlagError("--blur must be in [0, 50]");
    if (opt.photo.max_side < 0) throw FlagError("--max-side must be >= 0");
  } catch (const std::exception& e) {
    std::cerr << "nudge-detect: " << e.what() << "\n";
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
