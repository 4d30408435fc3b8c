// Fast, exact voting for Algorithm 1.
//
// Per theta bin the plain algorithm rotates every edge pixel, groups them into rows of Rot and
// checks every pair of every row against [Dmin, Dmax]. Here the same votes are cast with far less
// work:
//  * Rotation is integer fixed-point (quantise.hpp), a loop the compiler vectorises.
//  * Rows are built by one counting sort. The pixels are visited in an order in which x' is
//    already almost monotone along every row of Rot (column-major for |theta| <= 45 deg, row-major
//    otherwise; see below), so the rows come out nearly sorted and an insertion sort finishes them
//    in linear time.
//  * In a sorted row the partners of x_i that satisfy Dmin <= x_j - x_i <= Dmax are a contiguous
//    window found by two monotone pointers, so pairs outside [Dmin, Dmax] cost nothing and a vote is
//    one increment: fine[x_i + x_j]++. The fine array (quarter-pixel R) is folded into 1 px bins
//    once per theta.
// Why the visiting order works: on a row of Rot (fixed y'), x' = u / cos(theta) + y' tan(theta), so
// x' increases with u when |theta| < 90 deg; inside the 1 px high row y' varies by < 1, moving x' by
// at most |tan(theta)| <= 1 px for |theta| <= 45 deg. For |theta| > 45 deg the same holds with v
// (x' = v / sin(theta) - y' / tan(theta)), in reverse order when theta < 0.
#include <algorithm>
#include <cstring>
#include <thread>

#include "nudge/symmetry/detector.hpp"
#include "quantise.hpp"

namespace nudge::symmetry {

using detail::Layout;
using detail::ThetaTable;

namespace {

// Sort an almost-sorted short run in place (elements are at most a few places from home).
inline void insertion_sort(int32_t* x, int n) {
  for (int i = 1; i < n; ++i) {
    const int32_t v = x[i];
    int j = i - 1;
    while (j >= 0 && x[j] > v) {
      x[j + 1] = x[j];
      --j;
    }
    x[j + 1] = v;
  }
}

// All votes of one sorted row: every pair with dmin2 <= x_j - x_i <= dmax2 increments
// fine[x_i + x_j + shift] (shift folds in the skew offset of this row and the array offset).
inline void vote_row(const int32_t* x, int n, int32_t dmin2, int32_t dmax2, int32_t* fine_shifted) {
  int lo = 0, hi = 0;
  for (int i = 0; i < n; ++i) {
    const int32_t lo_val = x[i] + dmin2;
    const int32_t hi_val = x[i] + dmax2;
    if (lo <= i) lo = i + 1;
    while (lo < n && x[lo] < lo_val) ++lo;
    if (hi < lo) hi = lo;
    while (hi < n && x[hi] <= hi_val) ++hi;
    int32_t* base = fine_shifted + x[i];
    for (int j = lo; j < hi; ++j) ++base[x[j]];
  }
}

// The same votes, but a bin is incremented at most once per row (thesis sec. 3.2.3).
inline void vote_row_once(const int32_t* x, int n, int32_t dmin2, int32_t dmax2, int32_t shift,
                          const Layout& layout, int32_t row_id, int32_t* bins, int32_t* stamp) {
  int lo = 0, hi = 0;
  for (int i = 0; i < n; ++i) {
    if (lo <= i) lo = i + 1;
    while (lo < n && x[lo] < x[i] + dmin2) ++lo;
    if (hi < lo) hi = lo;
    while (hi < n && x[hi] <= x[i] + dmax2) ++hi;
    for (int j = lo; j < hi; ++j) {
      const int b = layout.bin_of_sum(x[i] + x[j] + shift);
      if (b < 0 || b >= layout.num_r() || stamp[b] == row_id) continue;
      stamp[b] = row_id;
      ++bins[b];
    }
  }
}

// Skew offsets are whole quarter-pixels of the pair sum: R_skew = x'_mid - y' tan(phi).
inline int32_t skew_shift(int row, double tan_phi) {
  return static_cast<int32_t>(std::lround(-4.0 * row * tan_phi));
}

// Largest |tan(phi)| in the skew list, rounded up: sizes the margins of the fine array.
int skew_margin(const std::vector<double>& skew_deg) {
  double m = 0;
  for (double s : skew_deg) m = std::max(m, std::fabs(std::tan(s * M_PI / 180.0)));
  return static_cast<int>(std::ceil(m));
}

}  // namespace

const Accumulator& Detector::vote(const EdgeSet& edges) {
  validate(params_);
  const Layout layout = detail::make_layout(edges.width, edges.height, params_);
  const int num_skews = 1 + static_cast<int>(params_.skew_deg.size());
  acc_.r_max = layout.r_max;
  acc_.votes.resize(num_skews);
  for (auto& m : acc_.votes) {
    m.create(kThetaBins, layout.num_r(), CV_32S);
    m.setTo(0);
  }
  // Two visiting orders of the edge pixels (see the comment at the top of this file).
  const size_t n = edges.points.size();
  by_row_u_.resize(n);
  by_row_v_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    by_row_u_[i] = 2 * edges.points[i].x - (edges.width - 1);
    by_row_v_[i] = 2 * edges.points[i].y - (edges.height - 1);
  }
  std::vector<int32_t> column_start(edges.width + 1, 0);
  for (const auto& p : edges.points) ++column_start[p.x + 1];
  for (int x = 0; x < edges.width; ++x) column_start[x + 1] += column_start[x];
  by_col_u_.resize(n);
  by_col_v_.resize(n);
  for (size_t i = 0; i < n; ++i) {  // stable: rows stay in increasing y within a column
    const int32_t k = column_start[edges.points[i].x]++;
    by_col_u_[k] = by_row_u_[i];
    by_col_v_[k] = by_row_v_[i];
  }

  const std::vector<int> thetas = theta_bins_in_range(params_.theta_min_deg, params_.theta_max_deg);
  const int num_threads = std::max(1, std::min<int>(params_.threads, static_cast<int>(thetas.size())));
  scratch_.resize(num_threads);
  if (num_threads == 1 || n == 0) {
    vote_thetas(edges, thetas, 0, 1, scratch_[0]);
  } else {
    std::vector<std::thread> workers;
    for (int t = 1; t < num_threads; ++t) {
      workers.emplace_back([&, t] { vote_thetas(edges, thetas, t, num_threads, scratch_[t]); });
    }
    vote_thetas(edges, thetas, 0, num_threads, scratch_[0]);
    for (auto& w : workers) w.join();
  }
  return acc_;
}

void Detector::vote_thetas(const EdgeSet& edges, const std::vector<int>& thetas, size_t first,
                           size_t step, Scratch& s) {
  const Layout layout = detail::make_layout(edges.width, edges.height, params_);
  const size_t n = by_row_u_.size();
  const int num_rows = 2 * layout.row_max + 1;
  const int margin = skew_margin(params_.skew_deg);
  // Fine array: index = xq_a + xq_b + skew shift + fine_offset, one cell per quarter pixel of R.
  const int32_t fine_offset = layout.sum_offset + 4 * (layout.r_max + 2) * margin;
  const size_t fine_size = static_cast<size_t>(2 * fine_offset + 8);
  s.xq.resize(n);
  s.row.resize(n);
  s.sorted.resize(n);
  s.starts.resize(num_rows + 1);
  s.fill.resize(num_rows);
  s.fine.assign(fine_size, 0);
  s.bins.assign(layout.num_r(), 0);
  s.stamp.assign(layout.num_r(), -1);
  std::vector<double> tan_skew;
  for (double d : params_.skew_deg) tan_skew.push_back(std::tan(d * M_PI / 180.0));

  for (size_t ti = first; ti < thetas.size(); ti += step) {
    const int k = thetas[ti];
    const ThetaTable t = detail::theta_table(k);
    const double theta_deg = theta_of_bin_deg(k);
    const bool by_column = std::fabs(theta_deg) <= 45.0;
    const int32_t* u = by_column ? by_col_u_.data() : by_row_u_.data();
    const int32_t* v = by_column ? by_col_v_.data() : by_row_v_.data();
    const bool reverse = !by_column && theta_deg < 0;

    // Rotate (vectorised) and count the pixels of each row of Rot.
    int32_t* xq = s.xq.data();
    int32_t* row = s.row.data();
    for (size_t i = 0; i < n; ++i) {
      xq[i] = detail::rotated_xq(u[i], v[i], t);
      row[i] = detail::rotated_row(u[i], v[i], t) + layout.row_max;
    }
    std::fill(s.starts.begin(), s.starts.end(), 0);
    for (size_t i = 0; i < n; ++i) ++s.starts[row[i] + 1];
    for (int r = 0; r < num_rows; ++r) s.starts[r + 1] += s.starts[r];
    // Scatter into rows, keeping the visiting order (so rows are nearly sorted).
    std::copy(s.starts.begin(), s.starts.end() - 1, s.fill.begin());
    int32_t* fill = s.fill.data();
    if (!reverse) {
      for (size_t i = 0; i < n; ++i) s.sorted[fill[row[i]]++] = xq[i];
    } else {
      for (size_t i = n; i-- > 0;) s.sorted[fill[row[i]]++] = xq[i];
    }

    for (int sk = 0; sk < static_cast<int>(acc_.votes.size()); ++sk) {
      const double tan_phi = sk == 0 ? 0.0 : tan_skew[sk - 1];
      int32_t* out = acc_.votes[sk].ptr<int32_t>(k);
      for (int r = 0; r < num_rows; ++r) {
        const int count = s.starts[r + 1] - s.starts[r];
        if (count < 2) continue;
        int32_t* x = s.sorted.data() + s.starts[r];
        if (sk == 0) insertion_sort(x, count);
        if (params_.max_row_pixels > 0 && count > params_.max_row_pixels) continue;
        const int32_t shift = sk == 0 ? 0 : skew_shift(r - layout.row_max, tan_phi);
        if (params_.once_per_row) {
          vote_row_once(x, count, layout.dmin2, layout.dmax2, shift, layout,
                        static_cast<int32_t>((k * static_cast<int>(acc_.votes.size()) + sk) * num_rows + r), s.bins.data(), s.stamp.data());
        } else {
          vote_row(x, count, layout.dmin2, layout.dmax2, s.fine.data() + fine_offset + shift);
        }
      }
      if (params_.once_per_row) {
        std::memcpy(out, s.bins.data(), sizeof(int32_t) * layout.num_r());
        std::fill(s.bins.begin(), s.bins.end(), 0);
        continue;
      }
      // Fold quarter-pixel cells into 1 px bins: bin b takes sums s with round(s/4) = b - r_max.
      for (int b = 0; b < layout.num_r(); ++b) {
        const int32_t sum_lo = 4 * (b - layout.r_max) - 2;
        const int32_t* f = s.fine.data() + fine_offset + sum_lo;
        out[b] = f[0] + f[1] + f[2] + f[3];
      }
      std::fill(s.fine.begin(), s.fine.end(), 0);
    }
  }
}

Accumulator reference_vote(const EdgeSet& edges, const Params& params) {
  validate(params);
  const Layout layout = detail::make_layout(edges.width, edges.height, params);
  Accumulator acc;
  acc.r_max = layout.r_max;
  acc.votes.assign(1 + params.skew_deg.size(), cv::Mat());
  for (auto& m : acc.votes) m = cv::Mat::zeros(kThetaBins, layout.num_r(), CV_32S);
  for (int k : theta_bins_in_range(params.theta_min_deg, params.theta_max_deg)) {
    const ThetaTable t = detail::theta_table(k);
    // Rotate every edge pixel and group by row of Rot.
    std::vector<std::vector<int32_t>> rows(2 * layout.row_max + 1);
    for (const auto& p : edges.points) {
      const int32_t u2 = 2 * p.x - (edges.width - 1), v2 = 2 * p.y - (edges.height - 1);
      rows[detail::rotated_row(u2, v2, t) + layout.row_max].push_back(detail::rotated_xq(u2, v2, t));
    }
    for (size_t sk = 0; sk < acc.votes.size(); ++sk) {
      const double tan_phi = sk == 0 ? 0.0 : std::tan(params.skew_deg[sk - 1] * M_PI / 180.0);
      int32_t* out = acc.votes[sk].ptr<int32_t>(k);
      for (size_t r = 0; r < rows.size(); ++r) {
        const auto& row = rows[r];
        if (params.max_row_pixels > 0 && static_cast<int>(row.size()) > params.max_row_pixels) continue;
        const int row_y = static_cast<int>(r) - layout.row_max;
        const int32_t shift = static_cast<int32_t>(std::lround(-4.0 * row_y * tan_phi));
        std::vector<char> voted(params.once_per_row ? layout.num_r() : 0, 0);
        // Every pair of the row, checked against [Dmin, Dmax].
        for (size_t i = 0; i < row.size(); ++i) {
          for (size_t j = i + 1; j < row.size(); ++j) {
            const int32_t dx = std::abs(row[i] - row[j]);
            if (dx < layout.dmin2 || dx > layout.dmax2) continue;
            const int b = layout.bin_of_sum(row[i] + row[j] + shift);
            if (b < 0 || b >= layout.num_r()) continue;
            if (params.once_per_row) {
              if (voted[b]) continue;
              voted[b] = 1;
            }
            ++out[b];
          }
        }
      }
    }
  }
  return acc;
}

}  // namespace nudge::symmetry
