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

std::vector<bool> found_in_scene(const Features& view, const Features& scene, double ratio, double static_px) {
  std::vector<bool> found(view.size(), false);
  if (view.size() == 0 || scene.size() < 2) return found;
  cv::BFMatcher matcher(cv::NORM_L2);
  matcher.add(scene.descriptors);
  for (const cv::DMatch& m : detail::ratio_matches(matcher, view.descriptors, scene.size(), ratio)) {
    const cv::Point2f shift = view.keypoints[m.queryIdx].pt - scene.keypoints[m.trainIdx].pt;
    if (shift.dot(shift) <= static_px * static_px) found[m.queryIdx] = true;
  }
  return found;
}

namespace {

// The scene still's features as a view's layer sees them: the same detection in the same box.
// The whole still is detected once; a squeezed layer once per box (views share their box as a rule).
class SceneFeatures {
 public:
  SceneFeatures(const cv::Mat& scene, const LearnParams& params) : scene_(scene), params_(params) {}
  const Features& in(size_t layer, const cv::Rect& box) {
    for (const Entry& e : cache_)
      if (e.layer == layer && e.box == box) return e.features;
    if (layer == 0 && !whole_detected_) whole_ = detect_features(scene_, params_.sift), whole_detected_ = true;
    const Features all = layer == 0 ? whole_ : detect_features_tilted(scene_, params_.axis_tilts[layer - 1], params_.sift, box);
    cache_.push_back({layer, box, features_inside(all, box)});
    return cache_.back().features;
  }

 private:
  Features whole_;  // layer 0 over the whole still
  bool whole_detected_ = false;
  struct Entry {
    size_t layer;
    cv::Rect box;
    Features features;
  };
  const cv::Mat& scene_;
  const LearnParams& params_;
  std::vector<Entry> cache_;  // a box or two: a list is enough (a reference from in() lasts until its next call)
};

}  // namespace

ObjectModel learn_object(const ObjectInfo& info, const std::vector<TrainingImage>& images, const LearnParams& params,
                         LearnStats* stats, const LearnProgress& progress, const cv::Mat& scene) {
  if (images.empty()) throw std::invalid_argument("object " + info.name + ": no training views");
  if (!scene.empty() && (scene.depth() != CV_8U || scene.size() != images.front().image.size()))
    throw std::invalid_argument("object " + info.name + ": the scene still is not 8-bit or not the views' size");
  if (!(params.mask_support >= 0))
    throw std::invalid_argument("object " + info.name + ": the mask support " + std::to_string(params.mask_support) + " is negative");
  for (double tilt : params.axis_tilts)
    if (!(tilt >= 1)) throw std::invalid_argument("object " + info.name + ": simulated tilt " + std::to_string(tilt) + " is below 1");
  LearnStats counts;
  // layers[0][v]: view v's features as taken; layers[l][v]: as seen squeezed by axis_tilts[l - 1].
  // Each layer is pruned on its own: a squeezed view is compared with the other views squeezed
  // alike (its own copy of a point in another layer would pass for its second neighbour).
  std::vector<std::vector<Features>> layers(1 + params.axis_tilts.size(), std::vector<Features>(images.size()));
  for (size_t v = 0; v < images.size(); ++v) {
    const TrainingImage& t = images[v];
    if (t.image.empty() || t.image.depth() != CV_8U)
      throw std::invalid_argument("object " + info.name + ": view " + std::to_string(v) + " is empty or not 8-bit");
    if (!t.mask.empty() && (t.mask.type() != CV_8UC1 || t.mask.size() != t.image.size()))
      throw std::invalid_argument("object " + info.name + ": view " + std::to_string(v) + "'s mask is not 8-bit single-channel of the view's size");
    const cv::Rect box = t.box.empty() ? cv::Rect() : generous_box(t.box, params.box_margin, t.image.size());
    for (size_t l = 0; l < layers.size(); ++l) {
      const Features all = l == 0 ? detect_features(t.image, params.sift)
                                  : detect_features_tilted(t.image, params.axis_tilts[l - 1], params.sift, box);
      const Features in_box = features_inside(all, box);
      layers[l][v] = features_on_mask(in_box, t.mask, params.mask_support);
      counts.detected += all.size();
      counts.outside_box += all.size() - in_box.size();
      counts.outside_mask += in_box.size() - layers[l][v].size();
    }
    if (progress) progress(static_cast<int>(v) + 1, static_cast<int>(images.size()));
  }
  std::vector<std::vector<std::vector<bool>>> background;
  for (const auto& layer : layers)
    background.push_back(background_descriptors(layer, params.ratio, params.background_matches, params.background_static_px));
  ObjectModel model;
  model.info = info;
  model.info.sift = params.sift;  // how its descriptors were found
  model.info.sift_recorded = true;
  SceneFeatures scene_features(scene, params);
  for (size_t v = 0; v < images.size(); ++v) {
    ModelView view;
    const cv::Rect box = images[v].box.empty() ? cv::Rect() : generous_box(images[v].box, params.box_margin, images[v].image.size());
    for (size_t l = 0; l < layers.size(); ++l) {
      std::vector<bool> keep(background[l][v].size());
      for (size_t k = 0; k < keep.size(); ++k) keep[k] = !background[l][v][k];
      int in_scene = 0;
      if (!scene.empty()) {
        const std::vector<bool> seen = found_in_scene(layers[l][v], scene_features.in(l, box), params.scene_ratio, params.scene_static_px);
        for (size_t k = 0; k < keep.size(); ++k)
          if (keep[k] && seen[k]) keep[k] = false, ++in_scene;
      }
      const Features kept = select_features(layers[l][v], keep);
      counts.scene += in_scene;
      counts.background += layers[l][v].size() - kept.size() - in_scene;
      view.features = l == 0 ? kept : concatenate(view.features, kept);
    }
    view.box = images[v].box;
    view.wrist_angle = images[v].wrist_angle;
    view.image = images[v].image;
    view.mask = images[v].mask;
    counts.kept += view.features.size();
    model.views.push_back(std::move(view));
  }
  if (stats) *stats = counts;
  return model;
}

}  // namespace nudge::learning
