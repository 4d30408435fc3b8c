// The tracker comparison's metric (issue 15): a perfect tracker of either kind scores about 0,
// a shifted one scores the shift, and the overlap score is the plain IoU.
#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "nudge/tracking/scoring.hpp"

namespace nudge::tracking {
namespace {

const cv::Size kImage(640, 480);

// An upright object: a filled rectangle whose symmetry axis is x = 300.5, from y = 100 to 299.
struct Upright {
  cv::Rect rect{281, 100, 40, 200};  // x 281..320: centre 300.5
  cv::Point2d bottom{300.5, 299}, top{300.5, 100};
  cv::Mat mask() const {
    cv::Mat m = cv::Mat::zeros(kImage, CV_8U);
    m(rect).setTo(255);
    return m;
  }
};

TEST(CentreLineError, PerfectBoxTrackerScoresZeroOnAnUprightObject) {
  const Upright o;
  const cv::Rect box = cv::boundingRect(o.mask());  // the true mask's bounding box
  EXPECT_NEAR(centre_line_error(centre_line_of_box(box), o.bottom, o.top), 0.0, 1e-9);
  EXPECT_NEAR(mask_iou(polygon_mask({cv::Point2f(281, 100), cv::Point2f(320, 100), cv::Point2f(320, 299),
                                     cv::Point2f(281, 299)}, kImage), o.mask()), 1.0, 1e-9);
}

TEST(CentreLineError, PerfectAxisTrackerScoresZeroAtAnyAngle) {
  // A tilted axis through (320, 200) at 35 deg from vertical, given in the polar form.
  const double tilt = 35 * M_PI / 180;
  const cv::Point2d mid(320, 200), along(std::sin(tilt), -std::cos(tilt));
  const cv::Point2d bottom = mid - 80.0 * along, top = mid + 80.0 * along;
  const cv::Point2d normal(-along.y, along.x);
  const cv::Point2d centre(0.5 * (kImage.width - 1), 0.5 * (kImage.height - 1));
  const double theta = std::atan2(normal.y, normal.x);
  const double r = (mid - centre).dot(normal);
  EXPECT_NEAR(centre_line_error(centre_line_of_polar(r, theta, kImage), bottom, top), 0.0, 1e-9);
  // The same line with theta turned by pi and r negated is the same line.
  EXPECT_NEAR(centre_line_error(centre_line_of_polar(-r, theta + M_PI, kImage), bottom, top), 0.0, 1e-9);
  // A rotated box along the axis: its long side is the axis.
  const cv::RotatedRect box(cv::Point2f(mid), cv::Size2f(30, 160), static_cast<float>(35.0));
  EXPECT_NEAR(centre_line_error(centre_line_of_rotated_box(box), bottom, top), 0.0, 1e-3);
  const cv::RotatedRect lying(cv::Point2f(mid), cv::Size2f(160, 30), static_cast<float>(35.0 - 90.0));
  EXPECT_NEAR(centre_line_error(centre_line_of_rotated_box(lying), bottom, top), 0.0, 1e-3);
}

TEST(CentreLineError, ShiftedTrackerScoresTheShift) {
  const Upright o;
  for (double shift : {-7.0, 2.5, 12.0}) {
    cv::Rect2d box(o.rect);
    box.x += shift;
    EXPECT_NEAR(centre_line_error(centre_line_of_box(box), o.bottom, o.top), std::abs(shift), 1e-9) << shift;
    // Shifted along the axis: no error.
    box = cv::Rect2d(o.rect);
    box.y += shift;
    EXPECT_NEAR(centre_line_error(centre_line_of_box(box), o.bottom, o.top), 0.0, 1e-9) << shift;
  }
  // A tilted axis, its estimate moved 5 px across it.
  const double tilt = -20 * M_PI / 180;
  const cv::Point2d mid(250, 260), along(std::sin(tilt), -std::cos(tilt)), normal(-along.y, along.x);
  const CentreLine shifted{mid + 5.0 * normal, along};
  EXPECT_NEAR(centre_line_error(shifted, mid - 60.0 * along, mid + 60.0 * along), 5.0, 1e-9);
}

TEST(CentreLineError, TurnedEstimateScoresItsMeanDistanceOverTheTrueExtent) {
  // Turned by a about the middle of a 200 px axis: distances |s| tan a for s in [-100, 100]; the
  // mean of 21 evenly spaced samples is 100 tan a * (2 * (1 + ... + 10) / 10) / 21.
  const Upright o;
  const double a = 10 * M_PI / 180;
  const cv::Point2d mid = 0.5 * (o.bottom + o.top);
  const CentreLine turned{mid, cv::Point2d(std::sin(a), std::cos(a))};
  const double half = 0.5 * cv::norm(o.top - o.bottom);
  const double expected = half * std::sin(a) * (2.0 * 55.0 / 10.0) / 21.0;
  EXPECT_NEAR(centre_line_error(turned, o.bottom, o.top), expected, 1e-9);
}

TEST(CentreLineError, BoxOnATiltedObjectIsTheFloor) {
  // A perfect box of a tilted object does not lie on its axis: the floor the table reports.
  cv::Mat mask = cv::Mat::zeros(kImage, CV_8U);
  const cv::RotatedRect body(cv::Point2f(320, 240), cv::Size2f(40, 200), 30.0f);
  cv::Point2f corners[4];
  body.points(corners);
  std::vector<cv::Point> poly;
  for (const auto& c : corners) poly.emplace_back(cvRound(c.x), cvRound(c.y));
  cv::fillConvexPoly(mask, poly, cv::Scalar(255));
  const CentreLine axis = centre_line_of_rotated_box(body);
  const cv::Point2d unit = axis.direction / cv::norm(axis.direction);
  const cv::Point2d bottom = axis.point - 100.0 * unit, top = axis.point + 100.0 * unit;
  const double floor = centre_line_error(centre_line_of_box(cv::boundingRect(mask)), bottom, top);
  // Samples at |s| <= 100 along a 30 deg tilt: mean |s| sin 30 = 50 * 0.5 * 22/21 ~ 26 px.
  EXPECT_NEAR(floor, 100.0 * 0.5 * (2.0 * 55.0 / 10.0) / 21.0, 1.0);
}

TEST(MaskIou, CountsOverlapOverUnion) {
  cv::Mat a = cv::Mat::zeros(kImage, CV_8U), b = cv::Mat::zeros(kImage, CV_8U);
  a(cv::Rect(0, 0, 20, 10)).setTo(255);   // 200 px
  b(cv::Rect(10, 0, 20, 10)).setTo(1);    // 200 px, 100 shared
  EXPECT_NEAR(mask_iou(a, b), 100.0 / 300.0, 1e-12);
  EXPECT_EQ(mask_iou(cv::Mat::zeros(kImage, CV_8U), cv::Mat::zeros(kImage, CV_8U)), 0.0);
  EXPECT_THROW(mask_iou(a, cv::Mat::zeros(10, 10, CV_8U)), std::invalid_argument);
  EXPECT_THROW(centre_line_error(CentreLine{{0, 0}, {0, 0}}, {0, 0}, {0, 1}), std::invalid_argument);
}

}  // namespace
}  // namespace nudge::tracking
