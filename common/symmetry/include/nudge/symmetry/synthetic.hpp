#pragma once
// Synthetic images with known symmetry axes, for tests, benchmarks and experiments.
#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

namespace nudge::symmetry::synthetic {

// A shape symmetric about an axis: half-widths sampled along the axis (top to bottom).
struct Profile {
  std::vector<double> half_width;  // px, one per step
  double step = 1.0;               // px between samples along the axis
  double length() const { return step * (half_width.size() - 1); }
};

Profile bottle_profile(double height, double body_half_width);
Profile cup_profile(double height, double top_half_width, double bottom_half_width);
Profile rectangle_profile(double height, double half_width);

// Outline polygon (image coordinates) of a profile whose axis is the line (r, theta) of a
// w x h image, centred along the axis at `along` px from the pivot point.
std::vector<cv::Point2d> outline(const Profile& profile, double r, double theta, double along, int width,
                                 int height);
// Draws the filled shape (anti-aliased, sub-pixel vertices) in `colour`.
void draw_shape(cv::Mat& image, const Profile& profile, double r, double theta, double along,
                const cv::Scalar& colour);

// A mug: cup body with a handle on one side (breaks the symmetry).
void draw_mug(cv::Mat& image, double r, double theta, double along, double height, double half_width,
              const cv::Scalar& colour);

// A 640x480-like indoor scene: shaded background, table edge, several objects (some symmetric),
// texture and clutter. Deterministic for a seed; Canny 30/90 gives several thousand edge pixels.
cv::Mat indoor_scene(uint32_t seed, int width = 640, int height = 480, int clutter = 3);

}  // namespace nudge::symmetry::synthetic
