#pragma once
// The Generalized Symmetry Transform (Reisfeld, Wolfson & Yeshurun 1995), as the reference the
// thesis compares fast symmetry against (sec. 3.5). Every pair of pixels with a gradient
// contributes to the symmetry magnitude at its midpoint:
//   C(i,j) = D_sigma(i,j) P(i,j) r_i r_j
//   D_sigma = exp(-|p_i - p_j| / (2 sigma)) / sqrt(2 pi sigma)
//   P = (1 - cos(t_i + t_j - 2 a_ij)) (1 - cos(t_i - t_j))
//   r = log(1 + |grad|), t = gradient direction, a_ij = direction of p_j - p_i.
// O(N^2) in the number of pixels with a gradient: seconds for a 101x101 image with a gradient
// everywhere, which is the point of the comparison.
#include <opencv2/core.hpp>

#include <cstdint>

namespace nudge::symmetry {

struct GstParams {
  double sigma = 2.0;
  double min_gradient = 1e-6;  // pixels with a smaller gradient magnitude take no part
};

struct GstResult {
  cv::Mat magnitude;  // CV_64F, same size as the image
  int64_t pairs = 0;  // pixel pairs evaluated
  double ms = 0;
};

GstResult generalized_symmetry(const cv::Mat& image, const GstParams& params);

}  // namespace nudge::symmetry
