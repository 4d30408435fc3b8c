// Which edge pairs voted for a detected line: for pictures (fig. 3.8) and for the line's support
// segment (the extent along the line that the voting pairs cover), which lets users score lines
// with the symmetry competitions' rule.
#include <algorithm>
#include <cmath>

#include "nudge/symmetry/detector.hpp"
#include "quantise.hpp"

namespace nudge::symmetry {

namespace {

// Calls visit(a, b) for every edge pair that voted into the line's discrete peak bin.
template <typename Visit>
void for_each_voting_pair(const EdgeSet& edges, const Params& params, const Line& line, Visit visit) {
  const detail::Layout layout = detail::make_layout(edges.width, edges.height, params);
  const detail::ThetaTable t = detail::theta_table(line.theta_bin);
  const double tan_phi =
      line.skew_index > 0 ? std::tan(params.skew_deg[line.skew_index - 1] * M_PI / 180.0) : 0.0;
  struct Item {
    int32_t xq, index;
  };
  const detail::MirrorRule mirror = detail::mirror_rule(line.theta_bin, params.mirror_tolerance_deg, params.mirror_polarity);
  const std::vector<int16_t>& angles = detail::mirror_angles(edges, params);
  const bool have_orientation = angles.size() == edges.points.size();
  // Group by row of Rot with one counting sort, then sort each (short) row by xq.
  const int num_rows = 2 * layout.row_max + 1;
  std::vector<int32_t> row_of(edges.points.size()), starts(num_rows + 1, 0);
  std::vector<Item> items(edges.points.size());
  for (size_t i = 0; i < edges.points.size(); ++i) {
    const int32_t u2 = 2 * edges.points[i].x - (edges.width - 1);
    const int32_t v2 = 2 * edges.points[i].y - (edges.height - 1);
    row_of[i] = detail::rotated_row(u2, v2, t) + layout.row_max;
    items[i] = {detail::rotated_xq(u2, v2, t), static_cast<int32_t>(i)};
    ++starts[row_of[i] + 1];
  }
  for (int r = 0; r < num_rows; ++r) starts[r + 1] += starts[r];
  std::vector<Item> sorted(items.size());
  {
    std::vector<int32_t> fill(starts.begin(), starts.end() - 1);
    for (size_t i = 0; i < items.size(); ++i) sorted[fill[row_of[i]]++] = items[i];
  }
  // Pair sums s with bin_of_sum(s + shift) == r_bin lie in [s_lo, s_lo + 3].
  const int32_t s_lo_base = 4 * (line.r_bin - layout.r_max) - 2;
  for (int r = 0; r < num_rows; ++r) {
    const int count = starts[r + 1] - starts[r];
    if (count < 2 || (params.max_row_pixels > 0 && count > params.max_row_pixels)) continue;
    const auto begin = sorted.begin() + starts[r], end = sorted.begin() + starts[r + 1];
    std::sort(begin, end, [](const Item& a, const Item& b) { return a.xq < b.xq; });
    const int32_t shift = static_cast<int32_t>(std::lround(-4.0 * (r - layout.row_max) * tan_phi));
    const int32_t s_lo = s_lo_base - shift;
    for (auto a = begin; a != end; ++a) {
      // Partners x_b in [s_lo - x_a, s_lo + 3 - x_a], after a, and within [Dmin, Dmax].
      const int32_t want_lo = std::max(s_lo - a->xq, a->xq + layout.dmin2);
      const int32_t want_hi = std::min(s_lo + 3 - a->xq, a->xq + layout.dmax2);
      if (want_lo > want_hi) continue;
      auto b = std::lower_bound(a + 1, end, want_lo, [](const Item& it, int32_t v) { return it.xq < v; });
      for (; b != end && b->xq <= want_hi; ++b) {
        if (mirror.on && (!have_orientation || !detail::mirror_consistent(angles[a->index], angles[b->index], mirror)))
          continue;
        visit(edges.points[a->index], edges.points[b->index]);
      }
    }
  }
}

}  // namespace

std::vector<VotingPair> Detector::voting_pairs(const EdgeSet& edges, const Line& line) const {
  std::vector<VotingPair> pairs;
  for_each_voting_pair(edges, params_, line, [&](cv::Point a, cv::Point b) { pairs.push_back({a, b}); });
  return pairs;
}

void Detector::add_support(const EdgeSet& edges, Line* line) const {
  // Project every voting pair's midpoint onto the (refined) line; the extremes are the segment.
  const double cx = 0.5 * (edges.width - 1), cy = 0.5 * (edges.height - 1);
  const cv::Point2d normal(std::cos(line->theta), std::sin(line->theta));
  const cv::Point2d dir(-normal.y, normal.x);
  const cv::Point2d pivot(cx + line->r * normal.x, cy + line->r * normal.y);
  double lo = 1e300, hi = -1e300;
  for_each_voting_pair(edges, params_, *line, [&](cv::Point a, cv::Point b) {
    const cv::Point2d mid(0.5 * (a.x + b.x), 0.5 * (a.y + b.y));
    const double s = (mid - pivot).dot(dir);
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  });
  if (lo > hi) return;
  line->seg1 = pivot + lo * dir;
  line->seg2 = pivot + hi * dir;
}

}  // namespace nudge::symmetry
