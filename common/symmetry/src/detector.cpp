#include "nudge/symmetry/detector.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "nudge/timing.hpp"
#include "quantise.hpp"

namespace nudge::symmetry {

namespace {
void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}
double deg2rad(double d) { return d * M_PI / 180.0; }
}  // namespace

void validate(const Params& p) {
  require(std::isfinite(p.dmin) && p.dmin >= 0, "symmetry parameter dmin must be a finite number >= 0");
  require(!std::isnan(p.dmax), "symmetry parameter dmax must be a number (<= 0 or inf: no limit)");
  require(!(p.dmax > 0) || std::isinf(p.dmax) || p.dmax >= p.dmin,
          "symmetry parameters: dmin must not exceed dmax");
  require(std::isfinite(p.theta_min_deg) && p.theta_min_deg >= -90 && p.theta_min_deg <= 90,
          "symmetry parameter theta_min must be in [-90, 90] degrees");
  require(std::isfinite(p.theta_max_deg) && p.theta_max_deg >= -90 && p.theta_max_deg <= 90,
          "symmetry parameter theta_max must be in [-90, 90] degrees");
  require(p.num_lines >= 0 && p.num_lines <= 1000, "symmetry parameter num_lines must be in [0, 1000]");
  require(std::isfinite(p.min_peak_ratio) && p.min_peak_ratio >= 0 && p.min_peak_ratio <= 1,
          "symmetry parameter min_peak_ratio must be in [0, 1]");
  require(p.suppress_r >= 0 && p.suppress_theta >= 0 && p.suppress_theta < 90,
          "symmetry parameters suppress_r >= 0 and suppress_theta in [0, 90) are required");
  require(p.max_row_pixels >= 0, "symmetry parameter max_row_pixels must be >= 0");
  require(p.threads >= 1 && p.threads <= 256, "symmetry parameter threads must be in [1, 256]");
  for (double s : p.skew_deg) {
    require(std::isfinite(s) && std::fabs(s) <= 60, "symmetry skew angles must be within [-60, 60] degrees");
  }
  require(std::isfinite(p.mirror_tolerance_deg) && p.mirror_tolerance_deg >= 0 && p.mirror_tolerance_deg <= 90,
          "symmetry parameter mirror_tolerance must be in [0, 90] degrees");
  require(!p.mirror_polarity || p.mirror_tolerance_deg > 0,
          "symmetry parameter mirror_polarity needs the mirror rule (mirror_tolerance > 0)");
  require(p.mirror_tolerance_deg == 0 || p.skew_deg.empty(),
          "symmetry parameters: mirror_tolerance does not combine with skew angles");
}

int16_t orientation_units(double radians) {
  // 65536 units = 180 deg; the int16 cast wraps, so the result is the angle modulo 180 deg.
  const double units = radians * (65536.0 / M_PI);
  const int64_t wrapped = std::llround(units - 65536.0 * std::floor(units / 65536.0)) & 0xFFFF;
  return static_cast<int16_t>(static_cast<uint16_t>(wrapped));
}

int16_t direction_units(double radians) { return orientation_units(0.5 * radians); }

void validate(const EdgeParams& p) {
  require(std::isfinite(p.blur_sigma) && p.blur_sigma >= 0 && p.blur_sigma <= 50,
          "edge parameter blur sigma must be in [0, 50]");
  require(std::isfinite(p.canny_low) && std::isfinite(p.canny_high) && p.canny_low >= 0 &&
              p.canny_high >= p.canny_low,
          "edge parameters: Canny thresholds must satisfy 0 <= low <= high");
}

std::vector<int> theta_bins_in_range(double theta_min_deg, double theta_max_deg) {
  std::vector<int> bins;
  for (int k = 0; k < kThetaBins; ++k) {
    const double t = theta_of_bin_deg(k);
    // theta = 90 is also theta = -90: a range starting at -90 includes the bin at +90.
    const double t_alt = (k == kThetaBins - 1) ? -90.0 : t;
    const bool inside = theta_min_deg <= theta_max_deg
                            ? (t >= theta_min_deg && t <= theta_max_deg) ||
                                  (t_alt >= theta_min_deg && t_alt <= theta_max_deg)
                            : (t >= theta_min_deg || t <= theta_max_deg || t_alt <= theta_max_deg);
    if (inside) bins.push_back(k);
  }
  return bins;
}

void remove_edges(EdgeSet& edges, const cv::Mat& exclude) {
  require(exclude.type() == CV_8UC1, "edge exclusion mask must be 8-bit single channel");
  require(exclude.cols == edges.width && exclude.rows == edges.height,
          "edge exclusion mask of " + std::to_string(exclude.cols) + "x" + std::to_string(exclude.rows) +
              " for edges of " + std::to_string(edges.width) + "x" + std::to_string(edges.height));
  const bool oriented = edges.orientation.size() == edges.points.size();
  const bool directed = edges.direction.size() == edges.points.size();
  size_t kept = 0;
  for (size_t i = 0; i < edges.points.size(); ++i) {
    const cv::Point p = edges.points[i];
    if (exclude.at<uint8_t>(p.y, p.x)) continue;
    edges.points[kept] = p;
    if (oriented) edges.orientation[kept] = edges.orientation[i];
    if (directed) edges.direction[kept] = edges.direction[i];
    ++kept;
  }
  edges.points.resize(kept);
  if (oriented) edges.orientation.resize(kept);
  if (directed) edges.direction.resize(kept);
}

EdgeSet edges_from_mask(const cv::Mat& mask) {
  require(mask.type() == CV_8UC1, "edge mask must be 8-bit single channel");
  EdgeSet edges;
  edges.width = mask.cols;
  edges.height = mask.rows;
  for (int y = 0; y < mask.rows; ++y) {
    const uint8_t* row = mask.ptr<uint8_t>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if (row[x]) edges.points.emplace_back(x, y);
    }
  }
  return edges;
}

namespace {
// EdgeSet::orientation from the 3x3 Sobel derivatives Canny used; on a colour image, those of
// the channel with the largest L1 gradient at each pixel (as OpenCV's Canny picks it).
void add_orientations(const cv::Mat& dx, const cv::Mat& dy, EdgeSet* edges) {
  const int channels = dx.channels();
  edges->orientation.resize(edges->points.size());
  edges->direction.resize(edges->points.size());
  for (size_t i = 0; i < edges->points.size(); ++i) {
    const cv::Point p = edges->points[i];
    const int16_t* gx = dx.ptr<int16_t>(p.y) + p.x * channels;
    const int16_t* gy = dy.ptr<int16_t>(p.y) + p.x * channels;
    int best = 0;
    for (int c = 1; c < channels; ++c)
      if (std::abs(gx[c]) + std::abs(gy[c]) > std::abs(gx[best]) + std::abs(gy[best])) best = c;
    const double angle = std::atan2(static_cast<double>(gy[best]), static_cast<double>(gx[best]));
    edges->orientation[i] = orientation_units(angle);
    edges->direction[i] = direction_units(angle);
  }
}

// Thresholds from the image itself, for photographs of any exposure: the high threshold is a high
// quantile (93 %) of the L1 gradient magnitude that Canny uses, the low one 40 % of it: a few per
// cent of the pixels become edges whatever the exposure or texture.
void auto_thresholds(const cv::Mat& image, double* low, double* high) {
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);  // colour edges: grey statistics
  cv::Mat gx, gy;
  cv::Sobel(grey, gx, CV_16S, 1, 0, 3);
  cv::Sobel(grey, gy, CV_16S, 0, 1, 3);
  cv::Mat mag;
  cv::add(cv::abs(gx), cv::abs(gy), mag, cv::noArray(), CV_32S);
  // Quantile from a histogram of the (small, integer) magnitudes: O(pixels), no sorting.
  std::vector<int64_t> histogram(4 * 255 * 2 + 2, 0);
  int64_t nonzero = 0;
  for (int y = 0; y < mag.rows; ++y) {
    const int* row = mag.ptr<int>(y);
    for (int x = 0; x < mag.cols; ++x) {
      if (row[x] > 0) {
        ++histogram[std::min<size_t>(static_cast<size_t>(row[x]), histogram.size() - 1)];
        ++nonzero;
      }
    }
  }
  if (nonzero == 0) {
    *low = 30;
    *high = 90;
    return;
  }
  const int64_t rank = static_cast<int64_t>(0.93 * (nonzero - 1));
  int64_t seen = 0;
  size_t value = 0;
  while (value + 1 < histogram.size() && seen + histogram[value] <= rank) seen += histogram[value++];
  *high = std::max(20.0, static_cast<double>(value));
  *low = 0.4 * *high;
}
}  // namespace

EdgeSet detect_edges(const cv::Mat& image, const EdgeParams& params, cv::Mat* edge_image) {
  validate(params);
  require(!image.empty(), "image is empty");
  require(image.depth() == CV_8U && (image.channels() == 1 || image.channels() == 3 || image.channels() == 4),
          "image must be 8-bit grey, BGR or BGRA");
  cv::Mat grey;  // the image Canny sees: grey, or BGR for colour edges
  if (image.channels() == 3 && params.colour) {
    grey = image;
  } else if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 4 && params.colour) {
    cv::cvtColor(image, grey, cv::COLOR_BGRA2BGR);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  } else {
    grey = image;
  }
  if (params.blur_sigma > 0) {
    cv::Mat blurred;  // a new buffer: `grey` may share the caller's pixels
    cv::GaussianBlur(grey, blurred, cv::Size(0, 0), params.blur_sigma);
    grey = blurred;
  }
  double low = params.canny_low, high = params.canny_high;
  if (params.auto_canny) auto_thresholds(grey, &low, &high);
  cv::Mat edges, dx, dy;
  const bool big_enough = grey.rows >= 3 && grey.cols >= 3;  // for a 3x3 aperture
  if (big_enough && params.gradients) {
    // The derivatives Canny would compute itself (3x3 Sobel, replicated border: the same edges,
    // pixel for pixel), kept for the orientations.
    cv::Sobel(grey, dx, CV_16S, 1, 0, 3, 1, 0, cv::BORDER_REPLICATE);
    cv::Sobel(grey, dy, CV_16S, 0, 1, 3, 1, 0, cv::BORDER_REPLICATE);
    cv::Canny(dx, dy, edges, low, high);
  } else if (big_enough) {
    cv::Canny(grey, edges, low, high, 3);
  } else {
    edges = cv::Mat::zeros(grey.size(), CV_8U);  // no edges
  }
  if (edge_image) *edge_image = edges;
  EdgeSet set = edges_from_mask(edges);
  if (params.gradients) {
    if (big_enough) add_orientations(dx, dy, &set);
    else set.orientation.assign(set.points.size(), 0);
    if (!big_enough) set.direction.assign(set.points.size(), 0);
  }
  return set;
}

void drop_weak_lines(std::vector<Line>& lines, double min_peak_ratio) {
  double top = 0;
  for (const Line& line : lines) top = std::max(top, line.votes);
  lines.erase(std::remove_if(lines.begin(), lines.end(), [&](const Line& line) { return line.votes < min_peak_ratio * top; }),
              lines.end());
}

Line map_line(const Line& line, cv::Size from, cv::Size to) {
  const double sx = static_cast<double>(to.width) / from.width, sy = static_cast<double>(to.height) / from.height;
  auto map_point = [&](cv::Point2d p) { return cv::Point2d((p.x + 0.5) * sx - 0.5, (p.y + 0.5) * sy - 0.5); };
  const cv::Point2d c_from(0.5 * (from.width - 1), 0.5 * (from.height - 1));
  const cv::Point2d n(std::cos(line.theta), std::sin(line.theta));
  const cv::Point2d d(-n.y, n.x);
  // Map two points of the line, then re-derive (R, theta) about the new centre.
  const cv::Point2d a = map_point(c_from + line.r * n), b = map_point(c_from + line.r * n + 100.0 * d);
  Line out = line;
  double theta = std::atan2(b.x - a.x, -(b.y - a.y));  // normal of the mapped direction
  if (theta > M_PI / 2) theta -= M_PI;
  if (theta <= -M_PI / 2) theta += M_PI;
  const cv::Point2d c_to(0.5 * (to.width - 1), 0.5 * (to.height - 1));
  out.theta = theta;
  out.r = (a - c_to).dot(cv::Point2d(std::cos(theta), std::sin(theta)));
  border_endpoints(out.r, out.theta, to.width, to.height, &out.end1, &out.end2);
  out.seg1 = map_point(line.seg1);
  out.seg2 = map_point(line.seg2);
  return out;
}

Detector::Detector(Params params, EdgeParams edge_params)
    : params_(std::move(params)), edge_params_(edge_params) {
  validate(params_);
  validate(edge_params_);
}

Result Detector::detect(const cv::Mat& image) {
  Stopwatch watch;
  EdgeParams edge_params = edge_params_;
  edge_params.gradients = edge_params.gradients || params_.mirror_tolerance_deg > 0;
  const EdgeSet edges = detect_edges(image, edge_params);
  const double edges_ms = watch.elapsed_ms();
  Result result = detect(edges);
  result.ms.edges_ms = edges_ms;
  return result;
}

Result Detector::detect(const EdgeSet& edges) {
  require(edges.width > 0 && edges.height > 0, "image is empty");
  require(edges.width <= detail::kMaxSide && edges.height <= detail::kMaxSide,
          "image is larger than 16384 px on a side");
  Result result;
  result.width = edges.width;
  result.height = edges.height;
  result.num_edges = static_cast<int>(edges.points.size());
  Stopwatch watch;
  vote(edges);
  result.ms.vote_ms = watch.lap_ms();
  result.lines = find_peaks(acc_, edges.width, edges.height);
  for (auto& line : result.lines) add_support(edges, &line);
  result.ms.peaks_ms = watch.lap_ms();
  return result;
}

namespace {

// Reads an accumulator layer with theta wrapping: bin 180 is bin 0 with R mirrored.
struct WrappedView {
  const cv::Mat& m;
  float at(int k, int b) const {
    bool mirror = false;
    if (k < 0) { k += kThetaBins; mirror = true; }
    if (k >= kThetaBins) { k -= kThetaBins; mirror = true; }
    if (mirror) b = m.cols - 1 - b;
    if (b < 0 || b >= m.cols) return 0.f;
    return m.at<float>(k, b);
  }
};

// Sub-bin refinement, eq. 3.1-3.2: Newton step on the 3x3 neighbourhood (x = R, y = theta).
// With log_votes the quadratic is fitted to log(1 + V), i.e. a Gaussian peak model: convergent
// voting gives sharp, non-parabolic peaks, and on synthetic shapes between bins this halves the
// worst angle error (0.50 -> 0.29 deg over 200 random bottles; see the unit tests).
cv::Point2d refine(const WrappedView& v, int k, int b, bool log_votes) {
  auto V = [&](int dr, int dt) {
    const double x = v.at(k + dt, b + dr);
    return log_votes ? std::log1p(x) : x;
  };
  const double v0 = V(0, 0);
  const double gr = (V(1, 0) - V(-1, 0)) / 2, gt = (V(0, 1) - V(0, -1)) / 2;
  const double hrr = V(1, 0) + V(-1, 0) - 2 * v0;
  const double htt = V(0, 1) + V(0, -1) - 2 * v0;
  const double hrt = (V(1, 1) + V(-1, -1) - V(-1, 1) - V(1, -1)) / 4;
  const double det = hrr * htt - hrt * hrt;
  double dr = 0, dt = 0;
  if (hrr < 0 && det > 1e-12) {  // a proper maximum: solve H x = -g
    dr = (-gr * htt + gt * hrt) / det;
    dt = (-gt * hrr + gr * hrt) / det;
  }
  if (!(std::fabs(dr) <= 1 && std::fabs(dt) <= 1)) {  // fall back to separate 1D parabolas
    dr = hrr < 0 ? -gr / hrr : 0;
    dt = htt < 0 ? -gt / htt : 0;
  }
  return {std::clamp(dr, -1.0, 1.0), std::clamp(dt, -1.0, 1.0)};
}

}  // namespace

std::vector<Line> Detector::find_peaks(const Accumulator& acc, int width, int height) const {
  std::vector<Line> lines;
  const int layers = static_cast<int>(acc.votes.size());
  std::vector<cv::Mat> work(layers);
  for (int l = 0; l < layers; ++l) {
    acc.votes[l].convertTo(work[l], CV_32F);
    if (params_.anti_alias) {
      // 3x3 Gaussian vote kernel == accumulator blur (linear); theta wraps with R mirrored.
      cv::Mat padded(kThetaBins + 2, work[l].cols, CV_32F);
      work[l].copyTo(padded.rowRange(1, kThetaBins + 1));
      cv::flip(work[l].row(kThetaBins - 1), padded.row(0), 1);
      cv::flip(work[l].row(0), padded.row(kThetaBins + 1), 1);
      cv::Mat blurred;
      cv::sepFilter2D(padded, blurred, CV_32F, cv::Mat(cv::Matx13f(0.25f, 0.5f, 0.25f)),
                      cv::Mat(cv::Matx31f(0.25f, 0.5f, 0.25f)), cv::Point(-1, -1), 0, cv::BORDER_CONSTANT);
      blurred.rowRange(1, kThetaBins + 1).copyTo(work[l]);
    }
  }
  // Per-row maxima make each of the Nlines searches O(rows) instead of O(bins).
  std::vector<std::vector<float>> row_max(layers, std::vector<float>(kThetaBins, 0.f));
  auto update_row = [&](int l, int k) {
    double mx;
    cv::minMaxLoc(work[l].row(k), nullptr, &mx);
    row_max[l][k] = static_cast<float>(mx);
  };
  for (int l = 0; l < layers; ++l)
    for (int k = 0; k < kThetaBins; ++k) update_row(l, k);

  float first_peak = 0;
  for (int i = 0; i < params_.num_lines; ++i) {
    int best_l = 0, best_k = 0;
    float best = 0;
    for (int l = 0; l < layers; ++l)
      for (int k = 0; k < kThetaBins; ++k)
        if (row_max[l][k] > best) { best = row_max[l][k]; best_l = l; best_k = k; }
    if (best <= 0) break;
    if (i == 0) first_peak = best;
    if (best < params_.min_peak_ratio * first_peak) break;
    cv::Point loc;
    cv::minMaxLoc(work[best_l].row(best_k), nullptr, nullptr, nullptr, &loc);
    const int b = loc.x;
    const cv::Point2d off = refine(WrappedView{work[best_l]}, best_k, b, params_.refine_log);

    Line line;
    line.votes = best;
    line.r_bin = b;
    line.theta_bin = best_k;
    line.skew_index = best_l;
    double r = b + off.x - acc.r_max;
    double theta_deg = theta_of_bin_deg(best_k + off.y);
    if (theta_deg > 90) { theta_deg -= 180; r = -r; }
    if (theta_deg <= -90) { theta_deg += 180; r = -r; }
    double theta = deg2rad(theta_deg);
    if (best_l > 0) {
      // Skew symmetry: pairs are horizontal in the rotated frame but their midpoints lie on
      // x' = R + y' tan(phi); that axis is the line (R cos(phi), theta - phi).
      const double phi = deg2rad(params_.skew_deg[best_l - 1]);
      line.skew = phi;
      r *= std::cos(phi);
      theta -= phi;
      if (theta > M_PI / 2) { theta -= M_PI; r = -r; }
      if (theta <= -M_PI / 2) { theta += M_PI; r = -r; }
    }
    line.r = r;
    line.theta = theta;
    border_endpoints(line.r, line.theta, width, height, &line.end1, &line.end2);
    line.seg1 = line.end1;
    line.seg2 = line.end2;
    lines.push_back(line);

    // Non-maximum suppression: zero the neighbourhood (wrapping in theta) in every layer.
    for (int dt = -params_.suppress_theta; dt <= params_.suppress_theta; ++dt) {
      int k = best_k + dt;
      bool mirror = false;
      if (k < 0) { k += kThetaBins; mirror = true; }
      if (k >= kThetaBins) { k -= kThetaBins; mirror = true; }
      for (int l = 0; l < layers; ++l) {
        float* row = work[l].ptr<float>(k);
        for (int dr = -params_.suppress_r; dr <= params_.suppress_r; ++dr) {
          int bb = b + dr;
          if (mirror) bb = work[l].cols - 1 - bb;
          if (bb >= 0 && bb < work[l].cols) row[bb] = 0.f;
        }
        update_row(l, k);
      }
    }
  }
  return lines;
}

}  // namespace nudge::symmetry
