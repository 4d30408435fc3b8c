#include "nudge/learning/synthetic.hpp"

#include <opencv2/imgproc.hpp>

#include <string>

namespace nudge::learning::synthetic {

cv::Mat random_texture(cv::Size size, uint64_t seed) {
  cv::RNG rng(seed);
  auto colour = [&rng](int lo, int hi) { return cv::Scalar(rng.uniform(lo, hi), rng.uniform(lo, hi), rng.uniform(lo, hi)); };
  cv::Mat image(size, CV_8UC3, colour(170, 255));
  const int area = size.area();
  const int shapes = std::max(20, area / 1500);
  auto point = [&] { return cv::Point(rng.uniform(0, size.width), rng.uniform(0, size.height)); };
  const int scale = std::max(4, std::min(size.width, size.height) / 12);
  for (int i = 0; i < shapes; ++i) {
    switch (rng.uniform(0, 4)) {
      case 0:
        cv::circle(image, point(), rng.uniform(2, scale), colour(0, 200), rng.uniform(-1, 3), cv::LINE_AA);
        break;
      case 1:
        cv::rectangle(image, cv::Rect(point(), cv::Size(rng.uniform(3, scale), rng.uniform(3, scale))), colour(0, 200),
                      rng.uniform(-1, 3));
        break;
      case 2:
        cv::line(image, point(), point(), colour(0, 200), rng.uniform(1, 4), cv::LINE_AA);
        break;
      default: {
        const std::string text(1, static_cast<char>('A' + rng.uniform(0, 26)));
        cv::putText(image, text + std::to_string(rng.uniform(0, 100)), point(), cv::FONT_HERSHEY_SIMPLEX,
                    rng.uniform(0.4, 1.6), colour(0, 150), rng.uniform(1, 3), cv::LINE_AA);
      }
    }
  }
  cv::GaussianBlur(image, image, cv::Size(3, 3), 0.7);
  return image;
}

std::vector<TrainingImage> turntable_views(const cv::Mat& surface, const cv::Mat& background, const cv::Rect& box,
                                           int views) {
  std::vector<TrainingImage> out;
  cv::Mat wrapped;
  cv::hconcat(surface, surface, wrapped);  // the label continues round the object
  for (int k = 0; k < views; ++k) {
    const int start = (k * surface.cols / views) % surface.cols;
    cv::Mat shown;
    cv::resize(wrapped(cv::Rect(start, 0, box.width, surface.rows)), shown, box.size(), 0, 0, cv::INTER_AREA);
    TrainingImage t;
    t.image = background.clone();
    shown.copyTo(t.image(box));
    t.box = box;
    t.wrist_angle = 2 * CV_PI * k / views;
    out.push_back(std::move(t));
  }
  return out;
}

cv::Mat place_in_scene(const cv::Mat& object, const cv::Mat& scene, double angle_deg, double scale, cv::Point2f centre) {
  cv::Mat transform = cv::getRotationMatrix2D(cv::Point2f(object.cols / 2.f, object.rows / 2.f), angle_deg, scale);
  transform.at<double>(0, 2) += centre.x - object.cols / 2.0;
  transform.at<double>(1, 2) += centre.y - object.rows / 2.0;
  cv::Mat warped, mask;
  cv::warpAffine(object, warped, transform, scene.size(), cv::INTER_LINEAR);
  cv::warpAffine(cv::Mat(object.size(), CV_8U, cv::Scalar(255)), mask, transform, scene.size(), cv::INTER_NEAREST);
  cv::Mat out = scene.clone();
  warped.copyTo(out, mask);
  return out;
}

ObjectModel object_model(const std::string& name, uint64_t seed, int views, cv::Size face) {
  const cv::Mat surface = random_texture({face.width * 4, face.height}, seed);
  const cv::Mat no_scene(face, CV_8UC3, cv::Scalar(128, 128, 128));
  ObjectModel model;
  model.info.name = name;
  for (const TrainingImage& t : turntable_views(surface, no_scene, cv::Rect(cv::Point(0, 0), face), views)) {
    ModelView view;
    view.image = t.image;
    view.features = detect_features(t.image);
    view.box = t.box;
    view.wrist_angle = t.wrist_angle;
    model.views.push_back(std::move(view));
  }
  return model;
}

std::vector<std::shared_ptr<const ObjectModel>> object_models(const std::string& prefix, int count, uint64_t first_seed) {
  std::vector<std::shared_ptr<const ObjectModel>> models;
  for (int i = 0; i < count; ++i)
    models.push_back(std::make_shared<const ObjectModel>(object_model(prefix + std::to_string(i), first_seed + i)));
  return models;
}

}  // namespace nudge::learning::synthetic
