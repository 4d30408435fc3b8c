#include "nudge/sim/mask_score.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace nudge::sim {

MaskScore score_mask(const cv::Mat& mask, const cv::Mat& labels, int objects) {
  if (mask.type() != CV_8UC1 || labels.type() != CV_8UC1)
    throw std::invalid_argument("score_mask: the mask and the labels must be 8-bit single-channel images");
  if (mask.size() != labels.size())
    throw std::invalid_argument("score_mask: a " + std::to_string(mask.cols) + "x" + std::to_string(mask.rows) +
                                " mask against " + std::to_string(labels.cols) + "x" + std::to_string(labels.rows) +
                                " true labels");
  MaskScore score;
  const cv::Mat segmented = mask != 0;
  score.mask_pixels = cv::countNonZero(segmented);
  int best_overlap = 0;
  for (int i = 0; i < objects; ++i) {
    const cv::Mat object = labels == i + 1;
    const int overlap = cv::countNonZero(object & segmented);
    if (overlap > best_overlap) {
      best_overlap = overlap;
      score.object = i;
      score.iou = static_cast<double>(overlap) / std::max(1, cv::countNonZero(object | segmented));
    }
  }
  return score;
}

}  // namespace nudge::sim
