#pragma once
// Matches judged against a simulator's truth (thesis Table 7.1's good and bad matches): a match is
// good when the query's keypoint and the training view's keypoint lie on the same surface point of
// the same object. Surface coordinates come from a renderer (nudge::sim::World::render_surface).
#include <opencv2/core.hpp>

#include <optional>
#include <string>
#include <vector>

namespace nudge::learning {

// What one image shows, pixel by pixel: which object (mask: label per pixel) and where on it
// (surface: CV_32FC3, metres in that object's own frame, NaN where no object is seen).
struct SurfaceTruth {
  cv::Mat surface;     // CV_32FC3
  cv::Mat mask;        // CV_8U, same size
  int label = 0;       // the mask value of the object of interest
  std::string object;  // its identity (the same name on both sides means the same object)
};

// The object's surface point under `pixel`: the nearest of its pixels within one pixel (a
// keypoint's centre may fall just off a silhouette), none when no pixel of the object is there.
std::optional<cv::Vec3f> surface_point(const SurfaceTruth& truth, cv::Point2f pixel);

struct MatchVerdicts {
  int good = 0, bad = 0;
  std::vector<double> distances_m;  // per match with both points on the object: how far apart
};

// Judges each match (queryIdx into `query`, trainIdx into `training`). Good: both keypoints lie
// on the object (surface_point), the two sides name the same object, and the surface points are
// within `tolerance_m` of each other. Everything else is bad. Throws std::out_of_range for an
// index outside its keypoints.
MatchVerdicts judge_matches(const std::vector<cv::DMatch>& matches, const std::vector<cv::KeyPoint>& query,
                            const SurfaceTruth& query_truth, const std::vector<cv::KeyPoint>& training,
                            const SurfaceTruth& training_truth, double tolerance_m);

}  // namespace nudge::learning
