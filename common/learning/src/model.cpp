#include "nudge/learning/model.hpp"

#include <opencv2/features2d.hpp>

#include <sstream>
#include <stdexcept>
#include <string>

#include "ratio_match.hpp"

namespace nudge::learning {

int ObjectModel::descriptor_count() const {
  int n = 0;
  for (const auto& view : views) n += view.features.size();
  return n;
}

std::vector<double> axis_tilts_from_text(const std::string& text) {
  std::vector<double> tilts;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    size_t used = 0;
    double tilt = 0;
    try {
      tilt = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (item.empty() || used != item.size() || !(tilt >= 1 && tilt <= 8))
      throw std::invalid_argument("simulated tilt '" + item + "' is no number in [1, 8]");
    tilts.push_back(tilt);
  }
  return tilts;
}

std::string axis_tilts_text(const std::vector<double>& tilts) {
  std::ostringstream out;
  for (size_t i = 0; i < tilts.size(); ++i) out << (i ? "," : "") << tilts[i];
  return out.str();
}

std::vector<std::vector<bool>> background_descriptors(const std::vector<Features>& views, double ratio,
                                                      int background_matches, double static_px) {
  std::vector<std::vector<int>> matched_views(views.size());
  for (size_t i = 0; i < views.size(); ++i) matched_views[i].assign(views[i].size(), 0);
  for (size_t j = 0; j < views.size(); ++j) {
    cv::BFMatcher matcher(cv::NORM_L2);
    matcher.add(views[j].descriptors);
    for (size_t i = 0; i < views.size(); ++i) {
      if (i == j) continue;
      for (const cv::DMatch& m : detail::ratio_matches(matcher, views[i].descriptors, views[j].size(), ratio)) {
        const cv::Point2f shift = views[i].keypoints[m.queryIdx].pt - views[j].keypoints[m.trainIdx].pt;
        if (static_px > 0 && shift.dot(shift) > static_px * static_px) continue;  // it moved: the object
        ++matched_views[i][m.queryIdx];
      }
    }
  }
  std::vector<std::vector<bool>> background(views.size());
  for (size_t i = 0; i < views.size(); ++i) {
    background[i].resize(views[i].size());
    for (int k = 0; k < views[i].size(); ++k) background[i][k] = matched_views[i][k] >= background_matches;
  }
  return background;
}

ObjectModel learn_object(const ObjectInfo& info, const std::vector<TrainingImage>& images, const LearnParams& params,
                         LearnStats* stats, const LearnProgress& progress) {
  if (images.empty()) throw std::invalid_argument("object " + info.name + ": no training views");
  for (double tilt : params.axis_tilts)
    if (!(tilt >= 1)) throw std::invalid_argument("object " + info.name + ": simulated tilt " + std::to_string(tilt) + " is below 1");
  LearnStats counts;
  std::vector<Features> boxed;
  for (size_t v = 0; v < images.size(); ++v) {
    const TrainingImage& t = images[v];
    if (t.image.empty() || t.image.depth() != CV_8U)
      throw std::invalid_argument("object " + info.name + ": view " + std::to_string(v) + " is empty or not 8-bit");
    Features all = detect_features(t.image, params.sift);
    const cv::Rect box = t.box.empty() ? cv::Rect() : generous_box(t.box, params.box_margin, t.image.size());
    for (double tilt : params.axis_tilts) all = concatenate(all, detect_features_tilted(t.image, tilt, params.sift, box));
    boxed.push_back(features_inside(all, box));
    counts.detected += all.size();
    counts.outside_box += all.size() - boxed.back().size();
    if (progress) progress(static_cast<int>(v) + 1, static_cast<int>(images.size()));
  }
  const auto background = background_descriptors(boxed, params.ratio, params.background_matches, params.background_static_px);
  ObjectModel model;
  model.info = info;
  for (size_t v = 0; v < images.size(); ++v) {
    std::vector<bool> keep(background[v].size());
    for (size_t k = 0; k < keep.size(); ++k) keep[k] = !background[v][k];
    ModelView view;
    view.features = select_features(boxed[v], keep);
    view.box = images[v].box;
    view.wrist_angle = images[v].wrist_angle;
    view.image = images[v].image;
    counts.background += boxed[v].size() - view.features.size();
    counts.kept += view.features.size();
    model.views.push_back(std::move(view));
  }
  if (stats) *stats = counts;
  return model;
}

}  // namespace nudge::learning
