#include <opencv2/imgproc.hpp>

#include "nudge/symmetry/detector.hpp"

namespace nudge::symmetry {

cv::Mat to_bgr(const cv::Mat& image) {
  cv::Mat bgr;
  if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  else if (image.channels() == 4) cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
  else bgr = image.clone();
  return bgr;
}

namespace {
const cv::Scalar kColours[] = {{0, 0, 255}, {0, 200, 0}, {255, 80, 0}, {0, 200, 255}, {255, 0, 255}, {255, 255, 0}};
}  // namespace

cv::Mat draw_lines(const cv::Mat& background, const std::vector<Line>& lines) {
  cv::Mat out = to_bgr(background);
  for (size_t i = 0; i < lines.size(); ++i) {
    const cv::Scalar colour = kColours[i % 6];
    const Line& l = lines[i];
    cv::line(out, l.end1, l.end2, colour, 1, cv::LINE_AA);
    cv::line(out, l.seg1, l.seg2, colour, 3, cv::LINE_AA);
    cv::putText(out, std::to_string(i + 1), (l.seg1 + l.seg2) * 0.5 + cv::Point2d(4, 0),
                cv::FONT_HERSHEY_SIMPLEX, 0.5, colour, 1, cv::LINE_AA);
  }
  return out;
}

cv::Mat accumulator_image(const Accumulator& acc, int skew_index) {
  cv::Mat votes;
  acc.votes.at(skew_index).convertTo(votes, CV_32F);
  double mx = 0;
  cv::minMaxLoc(votes, nullptr, &mx);
  cv::Mat grey;
  votes.convertTo(grey, CV_8U, mx > 0 ? 255.0 / mx : 0.0);
  cv::Mat transposed;  // theta along x (180 columns), R along y
  cv::transpose(grey, transposed);
  cv::Mat coloured;
  cv::applyColorMap(transposed, coloured, cv::COLORMAP_INFERNO);
  return coloured;
}

cv::Mat draw_voting_pairs(const cv::Mat& background, const std::vector<VotingPair>& pairs, const Line& line) {
  cv::Mat out = to_bgr(background) * 0.4;
  for (const auto& p : pairs) {
    cv::line(out, p.a, p.b, cv::Scalar(80, 80, 80), 1);
  }
  for (const auto& p : pairs) {
    out.at<cv::Vec3b>(p.a) = cv::Vec3b(0, 255, 255);
    out.at<cv::Vec3b>(p.b) = cv::Vec3b(0, 255, 255);
  }
  cv::line(out, line.end1, line.end2, cv::Scalar(0, 0, 255), 1, cv::LINE_AA);
  return out;
}

}  // namespace nudge::symmetry
