// Good and bad matches against rendered surface coordinates (thesis Table 7.1).
#include "nudge/learning/match_truth.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace nudge::learning {

std::optional<cv::Vec3f> surface_point(const SurfaceTruth& truth, cv::Point2f pixel) {
  const int cx = static_cast<int>(std::lround(pixel.x)), cy = static_cast<int>(std::lround(pixel.y));
  std::optional<cv::Vec3f> nearest;
  double nearest_d2 = std::numeric_limits<double>::infinity();
  for (int y = cy - 1; y <= cy + 1; ++y) {
    for (int x = cx - 1; x <= cx + 1; ++x) {
      if (x < 0 || y < 0 || x >= truth.mask.cols || y >= truth.mask.rows) continue;
      if (truth.mask.at<uint8_t>(y, x) != truth.label) continue;
      const cv::Vec3f p = truth.surface.at<cv::Vec3f>(y, x);
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) continue;
      const double d2 = (x - pixel.x) * (x - pixel.x) + (y - pixel.y) * (y - pixel.y);
      if (d2 < nearest_d2) {
        nearest_d2 = d2;
        nearest = p;
      }
    }
  }
  return nearest;
}

MatchVerdicts judge_matches(const std::vector<cv::DMatch>& matches, const std::vector<cv::KeyPoint>& query,
                            const SurfaceTruth& query_truth, const std::vector<cv::KeyPoint>& training,
                            const SurfaceTruth& training_truth, double tolerance_m) {
  MatchVerdicts verdicts;
  const bool same_object = query_truth.object == training_truth.object;
  for (const cv::DMatch& m : matches) {
    const auto q = surface_point(query_truth, query.at(m.queryIdx).pt);
    const auto t = surface_point(training_truth, training.at(m.trainIdx).pt);
    if (!q || !t || !same_object) {
      ++verdicts.bad;
      continue;
    }
    const double distance = cv::norm(*q - *t);
    verdicts.distances_m.push_back(distance);
    (distance <= tolerance_m ? verdicts.good : verdicts.bad)++;
  }
  return verdicts;
}

}  // namespace nudge::learning
