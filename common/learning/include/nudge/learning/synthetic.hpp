#pragma once
// Synthetic textured objects and scenes with known answers, for tests, benchmarks and experiments.
#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "nudge/learning/model.hpp"

namespace nudge::learning::synthetic {

// A BGR image of random shapes, lines and letters on a random light colour: SIFT finds plenty.
// The same seed gives the same image.
cv::Mat random_texture(cv::Size size, uint64_t seed);

// The views of an object turned in front of a static background, like the arm's turntable
// (thesis fig. 7.5): the object shows `box.width` columns of `surface` (its unrolled label),
// starting `k * surface.cols / views` columns further round for view k (wrapping), pasted into
// `background` at `box`. Each view's wrist angle is 2*pi*k/views.
std::vector<TrainingImage> turntable_views(const cv::Mat& surface, const cv::Mat& background, const cv::Rect& box,
                                           int views);

// `object` rotated by angle_deg, scaled by `scale` and pasted with its centre at `centre` into a
// copy of `scene`.
cv::Mat place_in_scene(const cv::Mat& object, const cv::Mat& scene, double angle_deg, double scale,
                       cv::Point2f centre);

// A model of an object whose unrolled label is random_texture(seed): `views` turntable views of
// `face` pixels each (the object alone, no scene: nothing to prune). For databases of many objects.
ObjectModel object_model(const std::string& name, uint64_t seed, int views = 12, cv::Size face = {120, 240});

// `count` such models named prefix + 0, 1, ... from seeds first_seed, first_seed + 1, ...: the
// stand-ins that fill a database to a size (benchmark, experiments' time at 100 objects).
std::vector<std::shared_ptr<const ObjectModel>> object_models(const std::string& prefix, int count, uint64_t first_seed);

}  // namespace nudge::learning::synthetic
