#pragma once
// Loy & Eklundh (2006), "Detecting symmetry and symmetric constellations of features": the
// standard baseline for bilateral symmetry in photographs. SIFT features are matched against the
// descriptors of their own mirror images; every match (i, j) votes for the perpendicular bisector
// of p_i p_j in a (R, theta) Hough space with weight
//   Phi = 1 - cos(phi_i + phi_j - 2 theta_ij)              (orientations mirror each other)
//   S   = exp(-|s_i - s_j| / (sigma_s (s_i + s_j)))^2      (similar scales)
// and the maxima of the blurred accumulator are the symmetry axes. Lines use the project's
// convention (R about the image centre, theta = 0 vertical); each line's support segment spans
// the midpoints of the matches that voted for it.
#include <opencv2/core.hpp>

#include <vector>

#include "nudge/symmetry/detector.hpp"

namespace nudge::symmetry {

struct LoyEklundhParams {
  int num_lines = 5;
  int matches_per_feature = 3;  // mirrored nearest neighbours kept per feature
  double sigma_scale = 1.0;     // sigma_s of the scale weight
  double blur_bins = 2.0;       // Gaussian blur of the accumulator, bins
  int max_features = 2000;
  int suppress_r = 10, suppress_theta = 10;  // non-maximum suppression, bins (px, deg)
};

std::vector<Line> loy_eklundh(const cv::Mat& image, const LoyEklundhParams& params = {});

}  // namespace nudge::symmetry
