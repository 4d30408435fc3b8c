#pragma once
// Lowe's ratio test on k = 2 nearest neighbours (private to nudge_learning).
#include <opencv2/features2d.hpp>

#include <vector>

namespace nudge::learning::detail {

// The nearest neighbour of each query row, kept when d1 < ratio * d2. A set of fewer than two
// descriptors has no second neighbour to compare with and matches nothing.
inline std::vector<cv::DMatch> ratio_matches(cv::DescriptorMatcher& matcher, const cv::Mat& query,
                                             int train_size, double ratio) {
  std::vector<cv::DMatch> out;
  if (query.empty() || train_size < 2) return out;
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(query, knn, 2);
  for (const auto& pair : knn) {
    if (pair.size() == 2 && pair[0].distance < ratio * pair[1].distance) out.push_back(pair[0]);
  }
  return out;
}

}  // namespace nudge::learning::detail
