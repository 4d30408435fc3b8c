#include "nudge/symmetry/verify.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace nudge::symmetry {

namespace {

// Mirrored sample positions inside a pair, as fractions of its half-length from the midpoint.
constexpr double kInside[] = {0.35, 0.6, 0.85};

cv::Vec3b colour_at(const cv::Mat& bgr, cv::Point2d p) {
  const int x = std::clamp(static_cast<int>(std::lround(p.x)), 0, bgr.cols - 1);
  const int y = std::clamp(static_cast<int>(std::lround(p.y)), 0, bgr.rows - 1);
  return bgr.at<cv::Vec3b>(y, x);
}

int l1(const cv::Vec3b& a, const cv::Vec3b& b) {
  return std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]);
}

struct Band {
  int pairs = 0;
  std::vector<cv::Point2d> midpoints;  // of the band's pairs
  // The support: the band and the runs beyond it joined across gaps up to support_gap (the
  // band itself when that gap is no wider than the band's).
  std::vector<cv::Point2d> support;
};

// The largest run of pair midpoints along the line with no gap wider than `gap`, and its support
// (the same run grown across gaps up to `support_gap`).
Band largest_band(const std::vector<double>& along, const std::vector<cv::Point2d>& midpoints, double gap,
                  double support_gap) {
  Band best;
  if (along.empty()) return best;
  std::vector<size_t> order(along.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return along[a] < along[b]; });
  size_t start = 0, best_start = 0;
  for (size_t i = 1; i <= order.size(); ++i) {
    if (i < order.size() && along[order[i]] - along[order[i - 1]] <= gap) continue;
    const int count = static_cast<int>(i - start);
    if (count > best.pairs) {
      best.pairs = count;
      best_start = start;
    }
    start = i;
  }
  const size_t best_end = best_start + static_cast<size_t>(best.pairs);  // one past the band
  for (size_t i = best_start; i < best_end; ++i) best.midpoints.push_back(midpoints[order[i]]);
  size_t lo = best_start, hi = best_end;
  const double join = std::max(gap, support_gap);
  while (lo > 0 && along[order[lo]] - along[order[lo - 1]] <= join) --lo;
  while (hi < order.size() && along[order[hi]] - along[order[hi - 1]] <= join) ++hi;
  for (size_t i = lo; i < hi; ++i) best.support.push_back(midpoints[order[i]]);
  return best;
}

cv::Mat as_bgr(const cv::Mat& image) {
  if (image.channels() == 3) return image;
  cv::Mat bgr;
  cv::cvtColor(image, bgr, image.channels() == 4 ? cv::COLOR_BGRA2BGR : cv::COLOR_GRAY2BGR);
  return bgr;
}

LineEvidence evidence_of(const std::vector<VotingPair>& pairs, const cv::Mat& bgr, const Line& line,
                         const VerifyParams& params, Band* band_out) {
  LineEvidence e;
  e.pairs = static_cast<int>(pairs.size());
  if (pairs.empty()) return e;
  const cv::Point2d centre(0.5 * (bgr.cols - 1), 0.5 * (bgr.rows - 1));
  const cv::Point2d normal(std::cos(line.theta), std::sin(line.theta)), dir(-normal.y, normal.x);
  std::vector<double> along;
  std::vector<cv::Point2d> midpoints;
  along.reserve(pairs.size());
  midpoints.reserve(pairs.size());
  int agree = 0, samples = 0;
  for (const VotingPair& p : pairs) {
    const cv::Point2d a(p.a), b(p.b), mid = 0.5 * (a + b), half = 0.5 * (b - a);
    along.push_back((mid - centre).dot(dir));
    midpoints.push_back(mid);
    for (double t : kInside) {
      agree += l1(colour_at(bgr, mid - t * half), colour_at(bgr, mid + t * half)) <= params.colour_tolerance;
      ++samples;
    }
  }
  Band band = largest_band(along, midpoints, params.band_gap_px, params.support_gap_px);
  e.band_share = static_cast<double>(band.pairs) / e.pairs;
  e.appearance = static_cast<double>(agree) / samples;
  e.score = line.votes * std::pow(e.band_share, params.band_weight) * std::pow(e.appearance, params.appearance_weight);
  if (band_out) *band_out = std::move(band);
  return e;
}

// The line refitted to its band's pair midpoints (VerifyParams::refine), or the line as it was.
Line refined(const Line& line, const Band& band, const VerifyParams& params, int width, int height) {
  if (!params.refine || band.pairs < params.refine_min_pairs) return line;
  const std::optional<Line> fit = fit_line(band.midpoints, width, height);
  if (!fit) return line;
  const LineDifference d = line_difference(*fit, line);
  if (std::fabs(d.theta) > params.refine_max_deg * M_PI / 180) return line;
  Line out = line;
  out.r = fit->r;
  out.theta = fit->theta;
  border_endpoints(out.r, out.theta, width, height, &out.end1, &out.end2);
  return out;
}

}  // namespace

std::optional<Line> fit_line(const std::vector<cv::Point2d>& points, int width, int height) {
  if (points.size() < 2) return std::nullopt;
  cv::Point2d mean(0, 0);
  for (const auto& p : points) mean += p;
  mean *= 1.0 / static_cast<double>(points.size());
  double sxx = 0, sxy = 0, syy = 0;
  for (const auto& p : points) {
    const cv::Point2d q = p - mean;
    sxx += q.x * q.x;
    sxy += q.x * q.y;
    syy += q.y * q.y;
  }
  if (sxx + syy <= 0) return std::nullopt;
  // The normal is the direction of least spread: the scatter matrix's smaller eigenvector.
  const double direction = 0.5 * std::atan2(2 * sxy, sxx - syy);
  double theta = direction + M_PI / 2;
  while (theta > M_PI / 2) theta -= M_PI;
  while (theta <= -M_PI / 2) theta += M_PI;
  const cv::Point2d centre(0.5 * (width - 1), 0.5 * (height - 1));
  Line line;
  line.theta = theta;
  line.r = (mean - centre).dot(cv::Point2d(std::cos(theta), std::sin(theta)));
  border_endpoints(line.r, line.theta, width, height, &line.end1, &line.end2);
  return line;
}

void validate(const VerifyParams& p) {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(what);
  };
  require(p.keep >= 0 && p.keep <= 1000, "verify parameter keep must be in [0, 1000]");
  require(p.band_gap_px > 0, "verify parameter band_gap_px must be > 0");
  require(p.support_gap_px >= 0, "verify parameter support_gap_px must be >= 0");
  require(p.colour_tolerance >= 0 && p.colour_tolerance <= 765, "verify parameter colour_tolerance must be in [0, 765]");
  require(p.min_appearance >= 0 && p.min_appearance <= 1, "verify parameter min_appearance must be in [0, 1]");
  require(p.appearance_weight >= 0 && p.appearance_weight <= 10, "verify parameter appearance_weight must be in [0, 10]");
  require(p.band_weight >= 0 && p.band_weight <= 10, "verify parameter band_weight must be in [0, 10]");
  require(p.suppress_px >= 0 && p.suppress_deg >= 0, "verify parameters suppress_px and suppress_deg must be >= 0");
  require(p.refine_max_deg >= 0 && p.refine_max_deg < 90, "verify parameter refine_max_deg must be in [0, 90)");
  require(p.refine_min_pairs >= 2, "verify parameter refine_min_pairs must be >= 2");
}

LineEvidence line_evidence(const Detector& detector, const EdgeSet& edges, const cv::Mat& image, const Line& line,
                           const VerifyParams& params) {
  validate(params);
  if (image.cols != edges.width || image.rows != edges.height)
    throw std::invalid_argument("verify: the image and its edge set differ in size");
  return evidence_of(detector.voting_pairs(edges, line), as_bgr(image), line, params, nullptr);
}

std::vector<Line> verify_lines(const Detector& detector, const EdgeSet& edges, const cv::Mat& image,
                               const std::vector<Line>& lines, const VerifyParams& params,
                               std::vector<LineEvidence>* evidence) {
  validate(params);
  if (image.cols != edges.width || image.rows != edges.height)
    throw std::invalid_argument("verify: the image and its edge set differ in size");
  const cv::Mat bgr = as_bgr(image);
  const cv::Point2d centre(0.5 * (bgr.cols - 1), 0.5 * (bgr.rows - 1));
  std::vector<Line> scored = lines;
  std::vector<LineEvidence> found(lines.size());
  for (size_t i = 0; i < lines.size(); ++i) {
    Band band;
    found[i] = evidence_of(detector.voting_pairs(edges, lines[i]), bgr, lines[i], params, &band);
    if (band.pairs > 0) {  // the support segment: the object's band (and what support_gap_px joins to it), not stray pairs along the line
      scored[i] = refined(lines[i], band, params, bgr.cols, bgr.rows);
      const cv::Point2d normal(std::cos(scored[i].theta), std::sin(scored[i].theta)), dir(-normal.y, normal.x);
      const cv::Point2d pivot = centre + scored[i].r * normal;
      double lo = 1e300, hi = -1e300;
      for (const cv::Point2d& m : band.support) {
        lo = std::min(lo, (m - centre).dot(dir));
        hi = std::max(hi, (m - centre).dot(dir));
      }
      scored[i].seg1 = pivot + lo * dir;
      scored[i].seg2 = pivot + hi * dir;
    }
  }
  std::vector<size_t> order(lines.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return found[a].score > found[b].score; });
  std::vector<Line> out;
  if (evidence) evidence->clear();
  auto near_kept = [&](const Line& line) {
    for (const Line& kept : out) {
      const LineDifference d = line_difference(line, kept);
      if (std::fabs(d.r) <= params.suppress_px && std::fabs(d.theta) <= params.suppress_deg * M_PI / 180) return true;
    }
    return false;
  };
  for (size_t i : order) {
    if (static_cast<int>(out.size()) >= params.keep) break;
    if (found[i].appearance < params.min_appearance || found[i].pairs == 0 || near_kept(scored[i])) continue;
    out.push_back(scored[i]);
    if (evidence) evidence->push_back(found[i]);
  }
  return out;
}

}  // namespace nudge::symmetry
