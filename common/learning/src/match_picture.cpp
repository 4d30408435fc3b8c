#include <opencv2/imgproc.hpp>

#include "nudge/learning/recognizer.hpp"

namespace nudge::learning {

namespace {
cv::Mat as_bgr(const cv::Mat& image) {
  cv::Mat bgr;
  if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  else bgr = image.clone();
  return bgr;
}
}  // namespace

cv::Mat draw_match_picture(const cv::Mat& query_image, const cv::Mat& training_image, const Features& training,
                           const Recognition& result) {
  const cv::Mat top = as_bgr(query_image), bottom = as_bgr(training_image);
  const int width = std::max(top.cols, bottom.cols);
  cv::Mat canvas(top.rows + bottom.rows, width, CV_8UC3, cv::Scalar(255, 255, 255));
  top.copyTo(canvas(cv::Rect(0, 0, top.cols, top.rows)));
  bottom.copyTo(canvas(cv::Rect(0, top.rows, bottom.cols, bottom.rows)));
  const ObjectScore* score = result.best_score();
  const cv::Point2f below(0, static_cast<float>(top.rows));
  const double scale = std::max(1.0, width / 640.0);
  if (score) {
    for (const cv::DMatch& m : score->matches) {
      const cv::Point2f q = result.query.keypoints[m.queryIdx].pt;
      const cv::Point2f t = training.keypoints[m.trainIdx].pt + below;
      cv::line(canvas, q, t, cv::Scalar(0, 0, 255), 1, cv::LINE_AA);
      cv::circle(canvas, q, 3, cv::Scalar(0, 0, 255), 1, cv::LINE_AA);
      cv::circle(canvas, t, 3, cv::Scalar(0, 0, 255), 1, cv::LINE_AA);
    }
  }
  const std::string label = score ? score->name + " (" + std::to_string(score->verified_matches) + " matches, view " +
                                        std::to_string(score->best_view) + ")"
                                  : "not recognised: " + result.reason;
  cv::putText(canvas, label, cv::Point(10, static_cast<int>(30 * scale)), cv::FONT_HERSHEY_SIMPLEX, 0.8 * scale,
              score ? cv::Scalar(0, 200, 0) : cv::Scalar(0, 0, 255), static_cast<int>(2 * scale), cv::LINE_AA);
  return canvas;
}

}  // namespace nudge::learning
