#include "nudge/symmetry/synthetic.hpp"

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <random>

namespace nudge::symmetry::synthetic {

Profile bottle_profile(double height, double body_half_width) {
  Profile p;
  const int n = std::max(8, static_cast<int>(height));
  p.step = height / (n - 1);
  for (int i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / (n - 1);  // 0 = top (cap), 1 = base
    double w;
    if (t < 0.08) w = 0.35;                                    // cap
    else if (t < 0.25) w = 0.3;                                // neck
    else if (t < 0.4) w = 0.3 + 0.7 * (t - 0.25) / 0.15;       // shoulder
    else w = 1.0;                                              // body
    p.half_width.push_back(w * body_half_width);
  }
  return p;
}

Profile cup_profile(double height, double top_half_width, double bottom_half_width) {
  Profile p;
  const int n = std::max(4, static_cast<int>(height));
  p.step = height / (n - 1);
  for (int i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / (n - 1);
    p.half_width.push_back(top_half_width + t * (bottom_half_width - top_half_width));
  }
  return p;
}

Profile rectangle_profile(double height, double half_width) {
  Profile p;
  p.step = height;
  p.half_width = {half_width, half_width};
  return p;
}

namespace {
struct Frame {
  cv::Point2d pivot, normal, dir;
};
Frame axis_frame(double r, double theta, int width, int height) {
  Frame f;
  f.normal = {std::cos(theta), std::sin(theta)};
  f.dir = {-f.normal.y, f.normal.x};
  f.pivot = cv::Point2d(0.5 * (width - 1), 0.5 * (height - 1)) + r * f.normal;
  return f;
}
}  // namespace

std::vector<cv::Point2d> outline(const Profile& profile, double r, double theta, double along, int width,
                                 int height) {
  const Frame f = axis_frame(r, theta, width, height);
  const double t0 = along - 0.5 * profile.length();
  std::vector<cv::Point2d> pts;
  const int n = static_cast<int>(profile.half_width.size());
  for (int i = 0; i < n; ++i)  // one side top to bottom
    pts.push_back(f.pivot + (t0 + i * profile.step) * f.dir + profile.half_width[i] * f.normal);
  for (int i = n - 1; i >= 0; --i)  // the mirror side back up
    pts.push_back(f.pivot + (t0 + i * profile.step) * f.dir - profile.half_width[i] * f.normal);
  return pts;
}

namespace {
void fill_polygon(cv::Mat& image, const std::vector<cv::Point2d>& pts, const cv::Scalar& colour) {
  constexpr int kShift = 4;  // sub-pixel vertex precision
  std::vector<cv::Point> fixed;
  for (const auto& p : pts)
    fixed.emplace_back(static_cast<int>(std::lround((p.x) * (1 << kShift))),
                       static_cast<int>(std::lround((p.y) * (1 << kShift))));
  const cv::Point* data = fixed.data();
  const int count = static_cast<int>(fixed.size());
  cv::fillPoly(image, &data, &count, 1, colour, cv::LINE_AA, kShift);
}
}  // namespace

void draw_shape(cv::Mat& image, const Profile& profile, double r, double theta, double along,
                const cv::Scalar& colour) {
  fill_polygon(image, outline(profile, r, theta, along, image.cols, image.rows), colour);
}

void draw_mug(cv::Mat& image, double r, double theta, double along, double height, double half_width,
              const cv::Scalar& colour) {
  draw_shape(image, cup_profile(height, half_width, 0.9 * half_width), r, theta, along, colour);
  // Handle: a thick ring segment on the +normal side.
  const Frame f = axis_frame(r, theta, image.cols, image.rows);
  const cv::Point2d centre = f.pivot + along * f.dir + (half_width * 0.95) * f.normal;
  const double angle = std::atan2(f.normal.y, f.normal.x) * 180.0 / M_PI;
  cv::ellipse(image, cv::Point(static_cast<int>(centre.x), static_cast<int>(centre.y)),
              cv::Size(static_cast<int>(0.45 * half_width), static_cast<int>(0.3 * height)), angle, -90, 90,
              colour, std::max(3, static_cast<int>(0.12 * half_width)), cv::LINE_AA);
}

cv::Mat indoor_scene(uint32_t seed, int width, int height, int clutter) {
  std::mt19937 rng(seed);
  auto uni = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  cv::Mat img(height, width, CV_8UC3);
  // Shaded wall and a table top below a horizon.
  const int horizon = static_cast<int>(height * uni(0.3, 0.45));
  for (int y = 0; y < height; ++y) {
    const double shade = y < horizon ? 150 + 50.0 * y / height : 110 + 40.0 * (y - horizon) / height;
    img.row(y).setTo(cv::Scalar(shade * uni(0.97, 1.0), shade, shade * 0.95));
  }
  // Clutter: posters, boxes and texture patches (asymmetric edges, as in real rooms).
  for (int i = 0; i < clutter * 3; ++i) {
    const cv::Point2d c(uni(0, width), uni(0, height));
    const cv::Size2f s(static_cast<float>(uni(15, 90)), static_cast<float>(uni(15, 90)));
    const cv::RotatedRect rect(c, s, static_cast<float>(uni(-40, 40)));
    cv::Point2f corners[4];
    rect.points(corners);
    std::vector<cv::Point> poly;
    for (auto& p : corners) poly.emplace_back(static_cast<int>(p.x), static_cast<int>(p.y));
    cv::fillConvexPoly(img, poly, cv::Scalar(uni(30, 230), uni(30, 230), uni(30, 230)), cv::LINE_AA);
  }
  for (int i = 0; i < clutter * 4; ++i) {  // short strokes: cables, shelf edges, shadows
    const cv::Point2d a(uni(0, width), uni(0, height));
    const double length = uni(15, 90), angle = uni(0, M_PI);
    const cv::Point2d b = a + length * cv::Point2d(std::cos(angle), std::sin(angle));
    cv::line(img, cv::Point(static_cast<int>(a.x), static_cast<int>(a.y)),
             cv::Point(static_cast<int>(b.x), static_cast<int>(b.y)), cv::Scalar(uni(0, 255), uni(0, 255), uni(0, 255)),
             static_cast<int>(uni(1, 4)), cv::LINE_AA);
  }
  for (int i = 0; i < clutter; ++i) {  // a patterned patch (book spines, tiles)
    const int x0 = static_cast<int>(uni(0, width - 100)), y0 = static_cast<int>(uni(0, height - 80));
    const int stripes = static_cast<int>(uni(4, 12));
    for (int k = 0; k < stripes; ++k) {
      cv::rectangle(img, cv::Rect(x0 + k * 9, y0, 7, static_cast<int>(uni(40, 80))),
                    cv::Scalar(uni(0, 255), uni(0, 255), uni(0, 255)), cv::FILLED);
    }
  }
  for (int i = 0; i < clutter * 40; ++i) {  // small marks: print, labels, wood grain, crumbs
    const cv::Point c(static_cast<int>(uni(0, width)), static_cast<int>(uni(0, height)));
    const cv::Size axes(static_cast<int>(uni(2, 9)), static_cast<int>(uni(1, 5)));
    cv::ellipse(img, c, axes, uni(0, 180), 0, 360, cv::Scalar(uni(0, 255), uni(0, 255), uni(0, 255)), cv::FILLED,
                cv::LINE_AA);
  }
  // Symmetric objects standing on the table: bottles, cups, mugs.
  const int objects = 4 + static_cast<int>(uni(0, 3));
  for (int i = 0; i < objects; ++i) {
    const double x = uni(0.1, 0.9) * width;
    const double h = uni(0.3, 0.55) * height;
    const double base = uni(horizon + 0.3 * (height - horizon), height - 5);
    const double theta = uni(-5, 5) * M_PI / 180.0;
    const double r = x - 0.5 * (width - 1);
    const double along = base - 0.5 * h - 0.5 * (height - 1);
    const cv::Scalar colour(uni(20, 250), uni(20, 250), uni(20, 250));
    switch (i % 3) {
      case 0: draw_shape(img, bottle_profile(h, uni(0.12, 0.2) * h), r, theta, along, colour); break;
      case 1: draw_shape(img, cup_profile(0.6 * h, 0.35 * h, 0.28 * h), r, theta, along, colour); break;
      default: draw_mug(img, r, theta, along, 0.55 * h, 0.3 * h, colour); break;
    }
  }
  // Sensor noise.
  cv::Mat noise(img.size(), CV_16SC3);
  cv::RNG noise_rng(seed * 2654435761u + 1);  // local RNG: OpenCV's global one is shared state
  noise_rng.fill(noise, cv::RNG::NORMAL, 0, 4);
  cv::Mat noisy;
  img.convertTo(noisy, CV_16SC3);
  noisy += noise;
  noisy.convertTo(img, CV_8UC3);
  return img;
}

}  // namespace nudge::symmetry::synthetic
