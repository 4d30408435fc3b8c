#include "nudge/symmetry/loy_eklundh.hpp"

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <stdexcept>

namespace nudge::symmetry {

namespace {

constexpr double kDeg = M_PI / 180.0;

struct Vote {
  double r, theta, weight;
  cv::Point2d midpoint;
};

// Mirrored descriptors: the descriptor of each keypoint's mirror image, computed on the flipped
// image at the mirrored position and orientation.
cv::Mat mirrored_descriptors(const cv::Mat& grey, const std::vector<cv::KeyPoint>& keypoints,
                             cv::Ptr<cv::SIFT>& sift, std::vector<int>* kept) {
  cv::Mat flipped;
  cv::flip(grey, flipped, 1);
  std::vector<cv::KeyPoint> mirrored = keypoints;
  for (size_t i = 0; i < mirrored.size(); ++i) {
    mirrored[i].pt.x = static_cast<float>(grey.cols - 1) - mirrored[i].pt.x;
    mirrored[i].angle = std::fmod(540.0f - mirrored[i].angle, 360.0f);
    mirrored[i].class_id = static_cast<int>(i);
  }
  cv::Mat descriptors;
  sift->compute(flipped, mirrored, descriptors);  // may drop keypoints near the border
  kept->clear();
  for (const auto& k : mirrored) kept->push_back(k.class_id);
  return descriptors;
}

std::vector<Vote> match_votes(const std::vector<cv::KeyPoint>& keypoints, const cv::Mat& descriptors,
                              const cv::Mat& mirrored, const std::vector<int>& mirrored_index, cv::Size size,
                              const LoyEklundhParams& params) {
  std::vector<std::vector<cv::DMatch>> matches;
  cv::BFMatcher(cv::NORM_L2).knnMatch(descriptors, mirrored, matches, params.matches_per_feature);
  const cv::Point2d centre(0.5 * (size.width - 1), 0.5 * (size.height - 1));
  std::vector<Vote> votes;
  for (const auto& list : matches) {
    for (const auto& m : list) {
      const int i = m.queryIdx, j = mirrored_index[m.trainIdx];
      if (i == j) continue;  // a feature matching its own mirror says nothing about an axis
      const cv::KeyPoint& a = keypoints[i];
      const cv::KeyPoint& b = keypoints[j];
      const cv::Point2d pa(a.pt), pb(b.pt);
      if (cv::norm(pb - pa) < 2.0) continue;
      double theta = std::atan2(pb.y - pa.y, pb.x - pa.x);  // the axis' normal
      const double phase = 1 - std::cos((a.angle + b.angle) * kDeg - 2 * theta);
      const double scale = std::exp(-std::fabs(a.size - b.size) / (params.sigma_scale * (a.size + b.size)));
      const cv::Point2d mid = 0.5 * (pa + pb);
      if (theta > M_PI / 2) theta -= M_PI;
      if (theta <= -M_PI / 2) theta += M_PI;
      const double r = (mid - centre).dot(cv::Point2d(std::cos(theta), std::sin(theta)));
      votes.push_back({r, theta, phase * scale * scale, mid});
    }
  }
  return votes;
}

}  // namespace

std::vector<Line> loy_eklundh(const cv::Mat& image, const LoyEklundhParams& params) {
  if (image.empty()) throw std::invalid_argument("image is empty");
  cv::Mat grey;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else grey = image;
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create(params.max_features);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  sift->detectAndCompute(grey, cv::noArray(), keypoints, descriptors);
  if (keypoints.size() < 2) return {};
  std::vector<int> mirrored_index;
  const cv::Mat mirrored = mirrored_descriptors(grey, keypoints, sift, &mirrored_index);
  if (mirrored.empty()) return {};
  const std::vector<Vote> votes = match_votes(keypoints, descriptors, mirrored, mirrored_index, grey.size(), params);

  // Hough accumulator over (theta bin of 1 deg, R bin of 1 px), blurred; theta wraps with R mirrored.
  const int r_max = static_cast<int>(std::ceil(0.5 * std::hypot(grey.cols, grey.rows))) + 1;
  cv::Mat acc = cv::Mat::zeros(kThetaBins, 2 * r_max + 1, CV_64F);
  auto bin_of = [&](double r, double theta, int* k, int* b) {
    *k = static_cast<int>(std::lround(theta / kDeg + 89.0));
    double rr = r;
    if (*k >= kThetaBins) { *k -= kThetaBins; rr = -rr; }
    if (*k < 0) { *k += kThetaBins; rr = -rr; }
    *b = static_cast<int>(std::lround(rr)) + r_max;
  };
  for (const auto& v : votes) {
    int k, b;
    bin_of(v.r, v.theta, &k, &b);
    if (b >= 0 && b < acc.cols) acc.at<double>(k, b) += v.weight;
  }
  cv::GaussianBlur(acc, acc, cv::Size(0, 0), params.blur_bins);
  std::vector<Line> lines;
  for (int n = 0; n < params.num_lines; ++n) {
    double best;
    cv::Point loc;
    cv::minMaxLoc(acc, nullptr, &best, nullptr, &loc);
    if (best <= 0) break;
    Line line;
    line.theta_bin = loc.y;
    line.r_bin = loc.x;
    line.votes = best;
    line.theta = theta_of_bin_deg(loc.y) * kDeg;
    line.r = loc.x - r_max;
    border_endpoints(line.r, line.theta, grey.cols, grey.rows, &line.end1, &line.end2);
    // Support: the midpoints of the matches that voted near this peak, projected on the line.
    const cv::Point2d centre(0.5 * (grey.cols - 1), 0.5 * (grey.rows - 1));
    const cv::Point2d normal(std::cos(line.theta), std::sin(line.theta)), dir(-normal.y, normal.x);
    const cv::Point2d pivot = centre + line.r * normal;
    double lo = 1e300, hi = -1e300;
    for (const auto& v : votes) {
      int k, b;
      bin_of(v.r, v.theta, &k, &b);
      if (std::abs(k - loc.y) > 2 || std::abs(b - loc.x) > 3 || v.weight <= 0) continue;
      const double s = (v.midpoint - pivot).dot(dir);
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
    line.seg1 = lo <= hi ? pivot + lo * dir : line.end1;
    line.seg2 = lo <= hi ? pivot + hi * dir : line.end2;
    lines.push_back(line);
    for (int dt = -params.suppress_theta; dt <= params.suppress_theta; ++dt) {
      int k = loc.y + dt;
      bool mirror = false;
      if (k < 0) { k += kThetaBins; mirror = true; }
      if (k >= kThetaBins) { k -= kThetaBins; mirror = true; }
      for (int dr = -params.suppress_r; dr <= params.suppress_r; ++dr) {
        int b = loc.x + dr;
        if (mirror) b = acc.cols - 1 - b;
        if (b >= 0 && b < acc.cols) acc.at<double>(k, b) = 0;
      }
    }
  }
  return lines;
}

}  // namespace nudge::symmetry
