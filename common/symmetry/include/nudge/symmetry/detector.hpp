#pragma once
// Fast bilateral symmetry detection (Li 2008, ch. 3, Algorithm 1).
//
// Lines follow the conventions of line.hpp: (R, theta) about the image centre, theta in (-90, 90] deg.
// The Hough accumulator has 180 theta bins of 1 degree (bin k <-> theta = k - 89 deg) and 1 px R bins.
#include <opencv2/core.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "nudge/symmetry/line.hpp"

namespace nudge::symmetry {

// Edge detection in front of the detector (thesis: OpenCV Canny, aperture 3, 30/90).
struct EdgeParams {
  double blur_sigma = 0.0;  // Gaussian blur before Canny; 0 = none
  double canny_low = 30.0;
  double canny_high = 90.0;
  bool auto_canny = false;  // derive the thresholds from the image's gradient statistics
  // Canny on the colour image (the gradient of the channel that changes most) instead of grey:
  // finds outlines between regions of equal brightness but different colour.
  bool colour = false;
  // Also measure each edge pixel's gradient orientation (EdgeSet::orientation), from the same
  // 3x3 Sobel derivatives Canny uses (on colour images: of the channel that changes most).
  bool gradients = false;
};

struct Params {
  double dmin = 25.0;          // minimum pairing distance, px
  double dmax = 250.0;         // maximum pairing distance, px; <= 0 or inf: no limit
  double theta_min_deg = -90;  // orientation limits, degrees; theta_min > theta_max wraps across +-90
  double theta_max_deg = 90;
  int num_lines = 5;           // Nlines
  double min_peak_ratio = 0.1; // reject peaks below this fraction of the highest peak
  int suppress_r = 10;         // non-maximum suppression half-size, R bins (px)
  int suppress_theta = 10;     // non-maximum suppression half-size, theta bins (deg)
  bool refine_log = true;      // sub-bin fit (eq. 3.1-3.2) on log(1 + votes); false: on raw votes
  // Extensions of thesis sec. 3.2.3 (all off by default: Algorithm 1 as published).
  int max_row_pixels = 0;      // straight-line suppression: skip rows of Rot with more pixels; 0 = off
  bool once_per_row = false;   // each row of Rot increments a given bin at most once
  bool anti_alias = false;     // 3x3 Gaussian vote kernel (applied as an accumulator blur)
  std::vector<double> skew_deg;// skew angles to vote for (skew symmetry); empty = bilateral only
  // Mirror-consistent pairs only: a pair votes for an axis only if the gradient orientations of
  // its two edge pixels are mirror images about that axis, within this many degrees. Random pairs
  // of texture and clutter rarely are, the two sides of a symmetric outline always are. Needs
  // EdgeSet::orientation (EdgeParams::gradients); not with skew. 0 = off (Algorithm 1 as published
  // uses edge locations only).
  double mirror_tolerance_deg = 0;
  // With the mirror rule: also the gradients' polarity must mirror (their directions modulo 360
  // deg, a + b = 2 theta + 180 deg: the same contrast on both sides of the axis, as an object on a
  // plain background shows). Needs EdgeSet::direction. Off by default: the thesis' rule is on
  // orientation only, and an object before a background brighter on one side than the other
  // shows opposite contrasts on its two sides.
  bool mirror_polarity = false;
  // With the mirror rule: keep each row of Rot grouped by orientation and check each pixel only
  // against the partners whose orientations can mirror its own about the current angle (the other
  // pairs cannot vote). Applies to the 32-bit pair loops (no AVX-512, vector_kernels = false, or
  // images too large for 16-bit lanes); the 16-bit AVX-512 loops check whole rows, which measured
  // faster, and here take their fast path: a row sort with no counter chain and fewer vector
  // operations per pair step (docs/results/mirror_voting.md). The accumulator is the same either
  // way; false is the plain mirror voting: every pair of every row, the plain row sort.
  bool mirror_sorted_rows = true;
  // false: the portable scalar pair loops even where AVX-512 is available (what builds without it
  // run; for tests and measurements). Same accumulator.
  bool vector_kernels = true;
  int threads = 1;             // threads across theta; results are identical for any count
};

// Throws std::invalid_argument naming the offending parameter.
void validate(const Params& params);
void validate(const EdgeParams& params);

// Edge pixel locations of one image, row-major order.
struct EdgeSet {
  int width = 0;
  int height = 0;
  std::vector<cv::Point> points;
  // Optional, one per point: the gradient's orientation modulo 180 deg (polarity-free) in units of
  // 180/65536 deg, so that int16 arithmetic wraps exactly as angles modulo 180 deg do.
  std::vector<int16_t> orientation;
  // Optional, one per point, filled with orientation: the gradient's direction modulo 360 deg (the
  // polarity kept) in units of 360/65536 deg (Params::mirror_polarity).
  std::vector<int16_t> direction;
};

// An angle (radians) as EdgeSet::orientation units, modulo 180 deg.
int16_t orientation_units(double radians);
// An angle (radians) as EdgeSet::direction units, modulo 360 deg.
int16_t direction_units(double radians);

struct Timing {
  double edges_ms = 0, vote_ms = 0, peaks_ms = 0;
  double total_ms() const { return edges_ms + vote_ms + peaks_ms; }
};

struct Result {
  int width = 0, height = 0;
  int num_edges = 0;
  std::vector<Line> lines;
  Timing ms;
};

// Hough accumulator: one CV_32S matrix of 180 x num_r per skew angle (index 0 = no skew).
struct Accumulator {
  int r_max = 0;                 // R bin b <-> R = b - r_max px
  std::vector<cv::Mat> votes;    // [skew index] -> 180 x (2 r_max + 1), CV_32S
  int num_r() const { return 2 * r_max + 1; }
};

// One edge pair that voted for a line (for pictures, fig. 3.8, and the support segment).
struct VotingPair {
  cv::Point a, b;
};

constexpr int kThetaBins = 180;
inline double theta_of_bin_deg(double bin) { return bin - 89.0; }

// The bins (0..179) whose centre lies inside [theta_min, theta_max] (wrapping if min > max).
std::vector<int> theta_bins_in_range(double theta_min_deg, double theta_max_deg);

// Canny edge pixels of an image (grey or colour, 8-bit).
EdgeSet detect_edges(const cv::Mat& image, const EdgeParams& params, cv::Mat* edge_image = nullptr);
EdgeSet edges_from_mask(const cv::Mat& mask);  // non-zero pixels of an 8-bit mask
// Drops the edge pixels where `exclude` (8-bit, the edges' image size) is non-zero, with their
// orientations: what the detector must not vote with (the robot's own body). Throws
// std::invalid_argument for a mask of another size or type.
void remove_edges(EdgeSet& edges, const cv::Mat& exclude);

// The same line in an image of another size (a resized copy of the same view): pixel centres
// map as x_to = (x_from + 0.5) * to.width / from.width - 0.5, and likewise in y. Meant for
// isotropic resizing; border endpoints and the support segment are mapped too.
Line map_line(const Line& line, cv::Size from, cv::Size to);

// Params::min_peak_ratio applied to lines already found: drops those with fewer votes than
// `min_peak_ratio` times the strongest of them. For lines filtered after detection (by where they
// stand, say), whose strongest may not be the accumulator's.
void drop_weak_lines(std::vector<Line>& lines, double min_peak_ratio);

class Detector {
 public:
  explicit Detector(Params params = {}, EdgeParams edge_params = {});

  const Params& params() const { return params_; }
  const EdgeParams& edge_params() const { return edge_params_; }

  // Full pipeline: edges, voting, peaks. Throws std::invalid_argument for an empty image.
  Result detect(const cv::Mat& image);
  Result detect(const EdgeSet& edges);

  // The pieces, for tests, benchmarks and pictures.
  const Accumulator& vote(const EdgeSet& edges);        // fast voting (this detector's scratch)
  std::vector<Line> find_peaks(const Accumulator& acc, int width, int height) const;
  const Accumulator& last_accumulator() const { return acc_; }
  std::vector<VotingPair> voting_pairs(const EdgeSet& edges, const Line& line) const;

 private:
  struct Scratch {  // per-thread working memory, kept between frames to avoid allocation
    std::vector<int32_t> xq, row, sorted, starts, fill, pairs, hist, stamp;
    std::vector<int16_t> sorted16, pairs16, angle16;  // angle16: orientations in row order
    // Windowed pair checks with the mirror rule: one row taken twice over, and where its
    // orientation buckets start.
    std::vector<int16_t> doubled_angle;
    std::vector<int32_t> doubled_x, bucket_start;
    // The mirror rule's ranked row sort (16-bit loops): each pixel's rank in its row, and the
    // pixels' x and angle as one word in row order.
    std::vector<uint16_t> rank;
    std::vector<uint32_t> packed, uv;  // uv: the pixels' (u2, v2) as two int16 in one word
  };
  template <typename Bin>
  void add_votes(const Bin* bins, int votes, size_t hist_size, Scratch& s, int shift = 0) const;
  template <typename Bin>
  void add_votes_once(const Bin* bins, int votes, int32_t row_id, Scratch& s, int shift = 0) const;
  void vote_thetas(const EdgeSet& edges, const std::vector<int>& thetas, size_t first, size_t step,
                   Scratch& scratch);
  void add_support(const EdgeSet& edges, Line* line) const;
  void prepare_pixels(const EdgeSet& edges, bool group_by_orientation);

  Params params_;
  EdgeParams edge_params_;
  Accumulator acc_;
  std::vector<Scratch> scratch_;
  // Edge pixels in doubled coordinates about the image centre (see quantise.hpp).
  // For windowed pair checks (Params::mirror_sorted_rows) grouped by orientation bucket: a stable
  // counting sort into rows then keeps every row grouped.
  std::vector<int32_t> u2_, v2_;
  std::vector<int16_t> angle_;  // the pixels' mirror-rule angles (detail::mirror_angles), in the order of u2_ and v2_
};

// Plain, obviously-correct Algorithm 1 (every pair of every row checked against Dmin/Dmax).
// Uses the same rotation table and quantisation as Detector::vote, so accumulators must be equal.
Accumulator reference_vote(const EdgeSet& edges, const Params& params);

// A 3-channel BGR copy of a grey, BGR or BGRA image, to draw on.
cv::Mat to_bgr(const cv::Mat& image);

// Visualisations (fig. 3.6-3.8): lines over the edges; the accumulator as an image.
cv::Mat draw_lines(const cv::Mat& background, const std::vector<Line>& lines);
cv::Mat accumulator_image(const Accumulator& acc, int skew_index = 0);
cv::Mat draw_voting_pairs(const cv::Mat& background, const std::vector<VotingPair>& pairs,
                          const Line& line);

}  // namespace nudge::symmetry
