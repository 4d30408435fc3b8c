#include "nudge/symmetry/corner_cutting.hpp"

#include <cmath>
#include <stdexcept>

#include "quantise.hpp"

namespace nudge::symmetry {

const Accumulator& CornerCuttingVoter::vote(const EdgeSet& edges, const Params& params) {
  validate(params);
  if (!params.skew_deg.empty() || params.mirror_tolerance_deg > 0)
    throw std::invalid_argument("the corner-cutting baseline votes for bilateral symmetry only");
  const detail::Layout layout = detail::make_layout(edges.width, edges.height, params);
  const int num_rows = 2 * layout.row_max + 1;
  const int capacity = 2 * layout.r_max + 2;  // a row of Rot holds at most an image diagonal
  rows_.resize(static_cast<size_t>(num_rows) * capacity);
  fill_.resize(num_rows);
  acc_.r_max = layout.r_max;
  acc_.votes.resize(1);
  acc_.votes[0].create(kThetaBins, layout.num_r(), CV_32S);  // kept between calls, as Detector's
  acc_.votes[0].setTo(0);
  const float cx = 0.5f * (edges.width - 1), cy = 0.5f * (edges.height - 1);
  const float dmin = static_cast<float>(params.dmin);
  const float dmax = params.dmax > 0 && std::isfinite(params.dmax) ? static_cast<float>(params.dmax) : 1e30f;
  for (int k : theta_bins_in_range(params.theta_min_deg, params.theta_max_deg)) {
    const double theta = theta_of_bin_deg(k) * M_PI / 180.0;
    const float c = static_cast<float>(std::cos(theta)), s = static_cast<float>(std::sin(theta));
    std::fill(fill_.begin(), fill_.end(), 0);
    for (const cv::Point& p : edges.points) {
      const float u = p.x - cx, v = p.y - cy;
      // Truncation of a positive value rounds (as cvaddon does): no libm call in the loop.
      const int row = static_cast<int>(v * c - u * s + static_cast<float>(layout.row_max) + 0.5f);
      rows_[static_cast<size_t>(row) * capacity + fill_[row]++] = u * c + v * s;
    }
    // Straight-line rejection: rows with twice the mean pixel count (of rows with a pair) or more.
    long pixels = 0, used_rows = 0;
    for (int r = 0; r < num_rows; ++r)
      if (fill_[r] >= 2) { pixels += fill_[r]; ++used_rows; }
    const float too_many = used_rows > 0 ? 2.0f * static_cast<float>(pixels / used_rows) : 0.f;
    int32_t* out = acc_.votes[0].ptr<int32_t>(k);
    const float bin0 = static_cast<float>(layout.r_max) + 0.5f;
    for (int r = 0; r < num_rows; ++r) {
      const int n = fill_[r];
      if (n < 2 || n >= too_many) continue;
      const float* x = rows_.data() + static_cast<size_t>(r) * capacity;
      for (int i = 0; i + 1 < n; ++i) {
        for (int j = i + 1; j < n; ++j) {
          const float d = std::fabs(x[j] - x[i]);
          if (d > dmax || d < dmin) break;  // the shortcut: the rest of the row is never looked at
          ++out[static_cast<int>(0.5f * (x[i] + x[j]) + bin0)];
        }
      }
    }
  }
  return acc_;
}

}  // namespace nudge::symmetry
