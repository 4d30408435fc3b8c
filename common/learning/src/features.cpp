#include "nudge/learning/features.hpp"

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace nudge::learning {

namespace {

void check_image_and_settings(const cv::Mat& image, const SiftParams& params) {
  if (image.empty()) throw std::invalid_argument("SIFT: empty image");
  if (image.depth() != CV_8U) throw std::invalid_argument("SIFT: image is not 8-bit");
  if (!(params.contrast_threshold > 0) || !(params.edge_threshold > 0) || params.octave_layers < 1)
    throw std::invalid_argument("SIFT: contrast_threshold and edge_threshold must be positive, octave_layers >= 1");
  if (!(params.equalise_clip >= 0) || params.equalise_tile_px < 8)
    throw std::invalid_argument("SIFT: equalise_clip must be >= 0 and equalise_tile_px >= 8");
}

// SIFT on a grey image as it is (no equalisation: the caller has done what it asked for).
Features sift_on_grey(const cv::Mat& grey, const SiftParams& params) {
  // One detector per thread (cv::SIFT keeps scratch state), made again when the settings change.
  thread_local cv::Ptr<cv::SIFT> sift;
  thread_local SiftParams made_with;
  if (!sift || made_with.contrast_threshold != params.contrast_threshold ||
      made_with.edge_threshold != params.edge_threshold || made_with.octave_layers != params.octave_layers) {
    sift = cv::SIFT::create(0, params.octave_layers, params.contrast_threshold, params.edge_threshold);
    made_with = params;
  }
  Features features;
  sift->detectAndCompute(grey, cv::noArray(), features.keypoints, features.descriptors);
  if (features.descriptors.empty()) features.descriptors.create(0, 128, CV_32F);
  return features;
}

}  // namespace

cv::Mat sift_grey(const cv::Mat& image, const SiftParams& params) {
  check_image_and_settings(image, params);
  cv::Mat grey;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else if (image.channels() == 4) cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  else grey = image;
  if (params.equalise_clip <= 0) return grey;
  // Tiles of a fixed size in pixels, not a fixed grid: the same camera's views and queries are
  // then equalised alike whatever the image's size.
  const cv::Size grid(std::max(1, (grey.cols + params.equalise_tile_px / 2) / params.equalise_tile_px),
                      std::max(1, (grey.rows + params.equalise_tile_px / 2) / params.equalise_tile_px));
  thread_local cv::Ptr<cv::CLAHE> clahe;
  if (!clahe) clahe = cv::createCLAHE();
  clahe->setClipLimit(params.equalise_clip);
  clahe->setTilesGridSize(grid);
  cv::Mat equalised;
  clahe->apply(grey, equalised);
  return equalised;
}

std::string sift_settings_difference(const SiftParams& a, const SiftParams& b) {
  std::string out;
  auto compare = [&out](const char* what, double x, double y) {
    if (x == y) return;
    std::ostringstream s;
    s << (out.empty() ? "" : ", ") << what << " " << x << " against " << y;
    out += s.str();
  };
  compare("contrast", a.contrast_threshold, b.contrast_threshold);
  compare("edge threshold", a.edge_threshold, b.edge_threshold);
  compare("octave layers", a.octave_layers, b.octave_layers);
  compare("equalisation clip", a.equalise_clip, b.equalise_clip);
  // The tile size matters only where equalisation is on.
  if (a.equalise_clip > 0 && b.equalise_clip > 0) compare("equalisation tile", a.equalise_tile_px, b.equalise_tile_px);
  return out;
}

cv::Mat keypoint_colours(const cv::Mat& image, const std::vector<cv::KeyPoint>& keypoints) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 3 && image.channels() != 4)) return {};
  cv::Mat bgr = image;
  if (image.channels() == 4) cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
  cv::Mat sums;  // (rows + 1) x (cols + 1), CV_64FC3
  cv::integral(bgr, sums, CV_64F);
  cv::Mat out(static_cast<int>(keypoints.size()), 3, CV_32F);
  for (int i = 0; i < out.rows; ++i) {
    const cv::KeyPoint& k = keypoints[i];
    const double tilt = at_simulated_tilt(k) ? k.class_id / 100.0 : 1;
    const double half_w = std::max(1.0, k.size / 2.0), half_h = std::max(1.0, k.size * tilt / 2.0);
    const int x0 = std::clamp(static_cast<int>(std::floor(k.pt.x - half_w)), 0, bgr.cols - 1);
    const int y0 = std::clamp(static_cast<int>(std::floor(k.pt.y - half_h)), 0, bgr.rows - 1);
    const int x1 = std::clamp(static_cast<int>(std::ceil(k.pt.x + half_w)), x0 + 1, bgr.cols);
    const int y1 = std::clamp(static_cast<int>(std::ceil(k.pt.y + half_h)), y0 + 1, bgr.rows);
    const cv::Vec3d total = sums.at<cv::Vec3d>(y1, x1) - sums.at<cv::Vec3d>(y0, x1) - sums.at<cv::Vec3d>(y1, x0) +
                            sums.at<cv::Vec3d>(y0, x0);
    const double area = static_cast<double>(x1 - x0) * (y1 - y0);
    for (int c = 0; c < 3; ++c) out.at<float>(i, c) = static_cast<float>(total[c] / area);
  }
  return out;
}

cv::Mat chromaticities(const cv::Mat& colours, int rows) {
  cv::Mat out(rows, 2, CV_32F, cv::Scalar(-1));
  if (colours.empty()) return out;
  if (colours.type() != CV_32F || colours.cols != 3 || colours.rows != rows)
    throw std::invalid_argument("chromaticities: " + std::to_string(colours.rows) + " colour rows of " +
                                std::to_string(colours.cols) + " for " + std::to_string(rows) + " keypoints");
  for (int i = 0; i < rows; ++i) {
    const float* c = colours.ptr<float>(i);
    const float sum = c[0] + c[1] + c[2];
    if (c[0] < 0 || sum < 3 * kMinColourLevel) continue;
    out.at<float>(i, 0) = c[2] / sum;  // r
    out.at<float>(i, 1) = c[1] / sum;  // g
  }
  return out;
}

Features detect_features(const cv::Mat& image, const SiftParams& params) {
  Features features = sift_on_grey(sift_grey(image, params), params);
  features.colours = keypoint_colours(image, features.keypoints);
  return features;
}

Features detect_features_tilted(const cv::Mat& image, double tilt, const SiftParams& params, const cv::Rect& roi) {
  if (!(tilt >= 1)) throw std::invalid_argument("SIFT: simulated tilt " + std::to_string(tilt) + " is below 1");
  if (image.empty()) throw std::invalid_argument("SIFT: empty image");
  const cv::Rect area = roi.empty() ? cv::Rect(0, 0, image.cols, image.rows) : roi & cv::Rect(0, 0, image.cols, image.rows);
  if (area.empty()) {  // the roi lies outside the image: nothing of it to see
    Features none;
    none.descriptors.create(0, 128, CV_32F);
    return none;
  }
  const int squeezed_rows = std::max(1, static_cast<int>(std::lround(area.height / tilt)));
  // Equalised as the whole view is, then squeezed: the layer's grey levels are the view's.
  const cv::Mat grey = sift_grey(image, params);
  cv::Mat squeezed;
  cv::resize(grey(area), squeezed, cv::Size(area.width, squeezed_rows), 0, 0, cv::INTER_AREA);
  Features features = sift_on_grey(squeezed, params);
  const float y_scale = static_cast<float>(area.height) / static_cast<float>(squeezed_rows);
  for (cv::KeyPoint& k : features.keypoints) {
    k.pt.x += static_cast<float>(area.x);
    k.pt.y = k.pt.y * y_scale + static_cast<float>(area.y);
    k.class_id = tilt_layer_id(tilt);
  }
  features.colours = keypoint_colours(image, features.keypoints);
  return features;
}

int tilt_layer_id(double tilt) { return tilt > 1 ? static_cast<int>(std::lround(tilt * 100)) : -1; }

Features concatenate(const Features& a, const Features& b) {
  Features out;
  out.keypoints = a.keypoints;
  out.keypoints.insert(out.keypoints.end(), b.keypoints.begin(), b.keypoints.end());
  cv::vconcat(a.descriptors.empty() ? cv::Mat(0, 128, CV_32F) : a.descriptors,
              b.descriptors.empty() ? cv::Mat(0, 128, CV_32F) : b.descriptors, out.descriptors);
  if (a.colours.empty() && b.colours.empty()) return out;
  // One side's colours unknown: rows of -1 for it (chromaticities treats them as agreeing with any).
  auto or_unknown = [](const Features& f) {
    return f.colours.empty() ? cv::Mat(f.size(), 3, CV_32F, cv::Scalar(-1)) : f.colours;
  };
  cv::vconcat(or_unknown(a), or_unknown(b), out.colours);
  return out;
}

cv::Mat root_sift(const cv::Mat& descriptors) {
  if (descriptors.empty()) return descriptors.clone();
  if (descriptors.type() != CV_32F) throw std::invalid_argument("root_sift: descriptors are not CV_32F");
  cv::Mat out(descriptors.size(), CV_32F);
  for (int r = 0; r < descriptors.rows; ++r) {
    const float* in = descriptors.ptr<float>(r);
    float* o = out.ptr<float>(r);
    double sum = 0;
    for (int c = 0; c < descriptors.cols; ++c) sum += std::abs(in[c]);
    const double scale = sum > 0 ? 1.0 / sum : 0.0;
    for (int c = 0; c < descriptors.cols; ++c) o[c] = static_cast<float>(std::sqrt(std::abs(in[c]) * scale));
  }
  return out;
}

cv::Rect generous_box(const cv::Rect& box, double margin, cv::Size image_size) {
  const int dx = static_cast<int>(box.width * margin), dy = static_cast<int>(box.height * margin);
  const cv::Rect grown(box.x - dx, box.y - dy, box.width + 2 * dx, box.height + 2 * dy);
  return grown & cv::Rect(cv::Point(0, 0), image_size);
}

Features select_features(const Features& features, const std::vector<bool>& keep) {
  Features out;
  out.descriptors.create(0, features.descriptors.empty() ? 128 : features.descriptors.cols, CV_32F);
  for (int i = 0; i < features.size(); ++i) {
    if (!keep[i]) continue;
    out.keypoints.push_back(features.keypoints[i]);
    out.descriptors.push_back(features.descriptors.row(i));
    if (!features.colours.empty()) out.colours.push_back(features.colours.row(i));
  }
  if (!features.colours.empty() && out.colours.empty()) out.colours.create(0, 3, CV_32F);
  return out;
}

Features features_inside(const Features& features, const cv::Rect& box) {
  if (box.empty()) return features;
  std::vector<bool> keep(features.size());
  for (int i = 0; i < features.size(); ++i) {
    const cv::Point2f& p = features.keypoints[i].pt;
    keep[i] = p.x >= box.x && p.y >= box.y && p.x < box.x + box.width && p.y < box.y + box.height;
  }
  return select_features(features, keep);
}

Features features_on_mask(const Features& features, const cv::Mat& mask, double support) {
  if (mask.empty()) return features;
  if (mask.type() != CV_8UC1) throw std::invalid_argument("the object mask is not 8-bit single-channel");
  if (!(support >= 0)) throw std::invalid_argument("the mask support " + std::to_string(support) + " is negative");
  // Each pixel's distance to the nearest pixel outside the mask (the image border counts as outside).
  cv::Mat inside = mask != 0, distance;
  cv::copyMakeBorder(inside, inside, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  cv::distanceTransform(inside, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  std::vector<bool> keep(features.size());
  for (int i = 0; i < features.size(); ++i) {
    const cv::KeyPoint& k = features.keypoints[i];
    const int x = cvRound(k.pt.x) + 1, y = cvRound(k.pt.y) + 1;
    if (x < 1 || y < 1 || x > mask.cols || y > mask.rows) continue;
    keep[i] = distance.at<float>(y, x) >= std::max(1.0, support * k.size / 2);
  }
  return select_features(features, keep);
}

}  // namespace nudge::learning
