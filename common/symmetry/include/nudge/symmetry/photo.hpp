#pragma once
// Symmetry detection on photographs of any size, with defaults that need no tuning: the image is
// detected at a working size (symmetry of whole objects is a coarse-scale property, and the cost
// grows with the square of the edge count), the pairing distances and blur scale with it, the
// Canny thresholds come from the image's gradients, and lines are mapped back to the photograph.
#include <opencv2/core.hpp>

#include <vector>

#include "nudge/symmetry/detector.hpp"

namespace nudge::symmetry {

// Photographs are full of texture whose edge pixels pair up by chance: there, only pairs whose
// edge orientations mirror about the axis vote (Params::mirror_tolerance_deg, 15 deg).
inline Params default_photo_params() {
  Params p;
  p.mirror_tolerance_deg = 15;
  return p;
}

struct PhotoOptions {
  Params params = default_photo_params();  // Nlines, orientation limits, extensions; dmin/dmax as below
  double dmin = -1;           // px at the working size; < 0: 5 % of the short side (>= 5 px)
  double dmax = -1;           // px at the working size; < 0: 50 % of the long side; 0: no limit
  double blur = -1;           // Gaussian sigma; < 0: max(1, short side / 480)
  std::vector<double> canny;  // {low, high}; empty: from the image (EdgeParams::auto_canny)
  int max_side = 480;         // working size: long side at most this, px; 0: the full image
};

struct PhotoDetection {
  Result in_image;            // lines in the photograph's own coordinates
  Result at_working_size;     // the same lines where they were detected
  cv::Mat working_image, edge_image;
  EdgeSet edges;              // at the working size
  Params params;              // what was actually used
  EdgeParams edge_params;
};

// Throws std::invalid_argument for an empty image or bad options (naming the option).
PhotoDetection detect_photo(const cv::Mat& image, const PhotoOptions& options);

// The symmetry-competition rule for one detected line against a human-annotated axis segment:
// the angle between them is below 10 deg and the distance between the centres of the detected
// support segment and the true segment is below 0.2 x the shorter of the two segments.
bool competition_match(const Line& detected, const cv::Point2d& truth_a, const cv::Point2d& truth_b,
                       double max_angle_deg = 10, double centre_fraction = 0.2);

}  // namespace nudge::symmetry
