#pragma once
// What the offline tools that read photographs share: the detection flags (with defaults that
// scale with the image, nudge::symmetry::PhotoOptions), numbered output files, and running over
// every image so that one unreadable file does not stop the others.
#include <opencv2/imgproc.hpp>

#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "nudge/flags.hpp"
#include "nudge/log.hpp"
#include "nudge/symmetry/photo.hpp"

namespace nudge::tools {

inline void add_photo_flags(Flags& flags, symmetry::PhotoOptions* o) {
  flags.add_int("lines", &o->params.num_lines, "symmetry lines per image (Nlines)");
  flags.add_double("dmin", &o->dmin, "minimum pairing distance, px (default: scaled)");
  flags.add_double("dmax", &o->dmax, "maximum pairing distance, px; 0 = none (default: scaled)");
  flags.add_double("theta-min", &o->params.theta_min_deg, "orientation limit, degrees");
  flags.add_double("theta-max", &o->params.theta_max_deg, "orientation limit, degrees (min > max wraps)");
  flags.add_doubles("canny", &o->canny, 2, "Canny thresholds LOW HIGH (default: from the image)");
  flags.add_double("blur", &o->blur, "Gaussian blur sigma before Canny; 0 = none (default: scaled)");
  flags.add_double("min-peak-ratio", &o->params.min_peak_ratio, "drop peaks below this fraction of the top");
  flags.add_int("suppress-r", &o->params.suppress_r, "non-maximum suppression half-size in R, px");
  flags.add_int("suppress-theta", &o->params.suppress_theta, "non-maximum suppression half-size, deg");
  flags.add_bool("once-per-row", &o->params.once_per_row, "a row of Rot increments a bin at most once");
  flags.add_int("max-row-pixels", &o->params.max_row_pixels, "skip rows of Rot with more pixels (0: off)");
  flags.add_double("mirror-tolerance", &o->params.mirror_tolerance_deg,
                   "pairs vote only if their edge orientations mirror about the axis within DEG (0: off)");
  flags.add_bool("mirror-polarity", &o->params.mirror_polarity,
                 "with --mirror-tolerance: the gradients' polarity must mirror too (same contrast on both sides)");
  flags.add_int("max-side", &o->max_side, "detect on a copy scaled to this long side, px (0: full size)");
}

// Throws std::invalid_argument / FlagError naming the option.
inline void validate_photo_options(const symmetry::PhotoOptions& o) {
  symmetry::Params check = o.params;
  check.dmin = std::max(0.0, o.dmin);
  check.dmax = o.dmax >= 0 ? o.dmax : 0;
  symmetry::validate(check);
  if (o.canny.size() == 2) symmetry::validate(symmetry::EdgeParams{0, o.canny[0], o.canny[1], false});
  if (o.blur > 50) throw FlagError("--blur must be in [0, 50]");
  if (o.max_side < 0) throw FlagError("--max-side must be >= 0");
}

// An image (e.g. the edges found at the working size) shown at another size, pixels kept crisp.
inline cv::Mat at_size(const cv::Mat& image, cv::Size size) {
  if (image.size() == size) return image;
  cv::Mat out;
  cv::resize(image, out, size, 0, 0, cv::INTER_NEAREST);
  return out;
}

// "out.png" -> "out_3.png" when several images are processed.
inline std::string numbered(const std::string& path, size_t index, size_t count) {
  if (count <= 1) return path;
  const auto dot = path.rfind('.');
  const std::string stem = dot == std::string::npos ? path : path.substr(0, dot);
  const std::string ext = dot == std::string::npos ? ".png" : path.substr(dot);
  return stem + "_" + std::to_string(index + 1) + ext;
}

// Runs process(path, index, count) on every image; a failure is reported and the others still
// run. Returns the exit code: 0 when all succeeded, 1 otherwise.
inline int run_on_images(const std::vector<std::string>& images,
                         const std::function<bool(const std::string&, size_t, size_t)>& process) {
  bool all_ok = true;
  for (size_t i = 0; i < images.size(); ++i) {
    try {
      all_ok &= process(images[i], i, images.size());
    } catch (const std::exception& e) {
      log::error() << images[i] << ": " << e.what();
      all_ok = false;
    }
  }
  return all_ok ? 0 : 1;
}

}  // namespace nudge::tools
